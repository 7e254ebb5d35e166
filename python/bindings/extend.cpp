// Bindings of the interior displacement (harmonic extension of a boundary field).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <morphomap/extend.hpp>

#include "interrupt_guard.hpp"

namespace py = pybind11;
using namespace morphomap;

namespace {

template <class Interior>
py::tuple interior_tuple(Interior&& out) {
  return py::make_tuple(std::move(out.points), std::move(out.cells), std::move(out.displacement), out.inverted,
                        out.min_jacobian, out.boundary_distance);
}

}  // namespace

void bind_extend(py::module_& m) {
  m.def(
      "extend_field_2d",
      [](const Points2Ref& starts, const Points2Ref& ends, const Points2Ref& source, const Points2Ref& points,
         const FacesRef& cells, double mesh_size) {
        InteriorField2 out;
        InterruptGuard interruptible;
        {
          py::gil_scoped_release release;
          out = extend_field(DisplacementField2{starts, ends, {}}, source, points, cells, mesh_size);
        }
        return interior_tuple(std::move(out));
      },
      py::arg("starts"), py::arg("ends"), py::arg("source"), py::arg("points"), py::arg("cells"),
      py::arg("mesh_size"));
  m.def(
      "extend_field_3d",
      [](const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces, const Points3Ref& points,
         const TetrahedraRef& cells) {
        InteriorField3 out;
        InterruptGuard interruptible;
        {
          py::gil_scoped_release release;
          out = extend_field(DisplacementField3{starts, ends, faces, {}}, points, cells);
        }
        return interior_tuple(std::move(out));
      },
      py::arg("starts"), py::arg("ends"), py::arg("faces"), py::arg("points"), py::arg("cells"));
}
