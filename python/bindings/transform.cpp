// Bindings of the Appendix A transformation: overlap area and the aligning similarity.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <morphomap/transform.hpp>

namespace py = pybind11;
using namespace morphomap;

void bind_transform(py::module_& m) {
  m.def("overlap_area", &overlap_area, py::arg("a"), py::arg("b"),
        py::call_guard<py::gil_scoped_release>());

  // Returns (centre (2,), scale, angle, translation (2,)).
  m.def(
      "align_curves",
      [](const Points2Ref& c1, const Points2Ref& c2, bool closed, double tolerance) {
        Similarity2 t;
        {
          py::gil_scoped_release release;
          t = align_curves(c1, c2, closed, tolerance);
        }
        return py::make_tuple(Vector(t.centre), t.scale, t.angle, Vector(t.translation));
      },
      py::arg("c1"), py::arg("c2"), py::arg("closed"), py::arg("tolerance"));
}
