// Bindings of the interior displacement (harmonic extension of a boundary field).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <morphomap/errors.hpp>
#include <morphomap/extend.hpp>

#include <string>

#include "interrupt_guard.hpp"

namespace py = pybind11;
using namespace morphomap;

namespace {

template <class Interior>
py::dict interior_record(Interior&& out) {
  return py::dict(py::arg("points") = std::move(out.points), py::arg("cells") = std::move(out.cells),
                  py::arg("displacement") = std::move(out.displacement), py::arg("inverted") = out.inverted,
                  py::arg("min_jacobian") = out.min_jacobian, py::arg("boundary_distance") = out.boundary_distance);
}

ExtensionMethod extension_method(const std::string& name) {
  if (name == "harmonic") return ExtensionMethod::harmonic;
  if (name == "elastic") return ExtensionMethod::elastic;
  throw InvalidInput("method: expected 'harmonic' or 'elastic', got '" + name + "'");
}

ExtendOptions extend_options(const std::string& method, double poisson_ratio, int substeps, bool untangle,
                             double mesh_size) {
  ExtendOptions options;
  options.untangle = untangle;
  options.method = extension_method(method);
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
        return interior_record(std::move(out));
      },
      py::arg("starts"), py::arg("ends"), py::arg("source"), py::arg("points"), py::arg("cells"), py::arg("method"),
      py::arg("poisson_ratio"), py::arg("substeps"), py::arg("untangle"), py::arg("mesh_size"));
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
        return interior_record(std::move(out));
      },
      py::arg("starts"), py::arg("ends"), py::arg("faces"), py::arg("points"), py::arg("cells"), py::arg("method"),
      py::arg("poisson_ratio"), py::arg("substeps"), py::arg("untangle"), py::arg("mesh_size"));
}
