// Bindings of the Appendix A transformation: overlap area and the aligning similarity.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <morphomap/transform.hpp>

namespace py = pybind11;
using namespace pybind11::literals;  // results cross as dicts keyed by field name
using namespace morphomap;

void bind_transform(py::module_& m) {
  m.def("overlap_area", &overlap_area, py::arg("a"), py::arg("b"), py::call_guard<py::gil_scoped_release>());

  m.def(
      "align_curves",
      [](const Points2Ref& c1, const Points2Ref& c2, bool closed, double tolerance) {
        Similarity2 t;
        {
          py::gil_scoped_release release;
          t = align_curves(c1, c2, closed, tolerance);
        }
        return py::dict("centre"_a = Vector(t.centre), "scale"_a = t.scale, "angle"_a = t.angle,
                        "translation"_a = Vector(t.translation));
      },
      py::arg("c1"), py::arg("c2"), py::arg("closed"), py::arg("tolerance"));

  // Similarity2::apply or apply_inverse: Python's Similarity carries the four numbers, the C++
  // core owns the formula.
  m.def(
      "apply_similarity",
      [](const Vec2& centre, double scale, double angle, const Vec2& translation, const Points2Ref& points,
         bool inverse) {
        const Similarity2 t{centre, scale, angle, translation};
        py::gil_scoped_release release;
        return inverse ? t.apply_inverse(points) : t.apply(points);
      },
      py::arg("centre"), py::arg("scale"), py::arg("angle"), py::arg("translation"), py::arg("points"),
      py::arg("inverse"));
}
