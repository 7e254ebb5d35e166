// Bindings of the field at any point of its source boundary (2D and 3D).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <morphomap/field_at.hpp>

namespace py = pybind11;
using namespace pybind11::literals;  // results cross as dicts keyed by field name
using namespace morphomap;

void bind_field_at(py::module_& m) {
  m.def(
      "displacement_at_2d",
      [](const Points2Ref& starts, const Points2Ref& ends, const Points2Ref& source, bool closed,
         const Points2Ref& points) {
        DisplacementAt2 at;
        {
          py::gil_scoped_release release;
          at = displacement_at(DisplacementField2{starts, ends, {}}, source, closed, points);
        }
        return py::dict("displacements"_a = std::move(at.displacements), "distances"_a = std::move(at.distances));
      },
      py::arg("starts"), py::arg("ends"), py::arg("source"), py::arg("closed"), py::arg("points"));
  m.def(
      "displacement_at_3d",
      [](const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces, const Points3Ref& points) {
        DisplacementAt3 at;
        {
          py::gil_scoped_release release;
          at = displacement_at(DisplacementField3{starts, ends, faces, {}}, points);
        }
        return py::dict("displacements"_a = std::move(at.displacements), "distances"_a = std::move(at.distances));
      },
      py::arg("starts"), py::arg("ends"), py::arg("faces"), py::arg("points"));
}
