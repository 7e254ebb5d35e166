// Bindings of the interior displacement (harmonic extension of a boundary field).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <morphomap/extend.hpp>

#include <string>

#include "interrupt_guard.hpp"

namespace py = pybind11;
using namespace morphomap;

namespace {

template <class Interior>
py::tuple interior_tuple(Interior&& out) {
  return py::make_tuple(std::move(out.points), std::move(out.cells), std::move(out.displacement), out.inverted,
                        out.min_jacobian, out.boundary_distance);
}

ExtendOptions extend_options(const std::string& method, double poisson_ratio, int substeps, bool untangle,
                             double mesh_size) {
  ExtendOptions options;
  options.untangle = untangle;
  options.method = method == "elastic" ? ExtensionMethod::elastic : ExtensionMethod::harmonic;
  options.poisson_ratio = poisson_ratio;
  options.substeps = substeps;
  options.mesh_size = mesh_size;
  return options;
}

}  // namespace

void bind_extend(py::module_& m) {
  m.def(
      "extend_field_2d",
      [](const Points2Ref& starts, const Points2Ref& ends, const Points2Ref& source, const Points2Ref& points,
         const FacesRef& cells, const std::string& method, double poisson_ratio, int substeps, bool untangle,
         double mesh_size) {
        const ExtendOptions options = extend_options(method, poisson_ratio, substeps, untangle, mesh_size);
        InteriorField2 out;
        InterruptGuard interruptible;
        {
          py::gil_scoped_release release;
          out = extend_field(DisplacementField2{starts, ends, {}}, source, points, cells, options);
        }
        return interior_tuple(std::move(out));
      },
      py::arg("starts"), py::arg("ends"), py::arg("source"), py::arg("points"), py::arg("cells"),
      py::arg("method"), py::arg("poisson_ratio"), py::arg("substeps"), py::arg("untangle"),
      py::arg("mesh_size"));
  m.def(
      "extend_field_3d",
      [](const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces, const Points3Ref& points,
         const TetrahedraRef& cells, const std::string& method, double poisson_ratio, int substeps, bool untangle,
         double mesh_size) {
        const ExtendOptions options = extend_options(method, poisson_ratio, substeps, untangle, mesh_size);
        InteriorField3 out;
        InterruptGuard interruptible;
        {
          py::gil_scoped_release release;
          out = extend_field(DisplacementField3{starts, ends, faces, {}}, points, cells, options);
        }
        return interior_tuple(std::move(out));
      },
      py::arg("starts"), py::arg("ends"), py::arg("faces"), py::arg("points"), py::arg("cells"),
      py::arg("method"), py::arg("poisson_ratio"), py::arg("substeps"), py::arg("untangle"),
      py::arg("mesh_size"));
}
