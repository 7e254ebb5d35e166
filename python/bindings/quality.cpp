// Bindings of the quality measures of a displacement field.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <morphomap/prepared_curve.hpp>
#include <morphomap/quality.hpp>

#include "interrupt_guard.hpp"

namespace py = pybind11;
using namespace pybind11::literals;  // results cross as dicts keyed by field name
using namespace morphomap;

namespace {

// quality of a 2D field on plain (Points2Ref) or prepared curves, bound under `name`.
template <class Curve>
void def_curve_quality(py::module_& m, const char* name) {
  m.def(
      name,
      [](const Points2Ref& starts, const Points2Ref& ends, const Curve& c1, const Curve& c2, bool closed) {
        CurveQuality q;
        InterruptGuard interruptible;
        {
          py::gil_scoped_release release;
          DisplacementField2 field{starts, ends, {}};
          q = quality(field, c1, c2, closed);
        }
        return py::dict("qm1"_a = q.qm1, "qm2"_a = q.qm2, "qm"_a = q.qm, "crossings"_a = q.crossings);
      },
      py::arg("starts"), py::arg("ends"), py::arg("c1"), py::arg("c2"), py::arg("closed"));
}

}  // namespace

void bind_quality(py::module_& m) {
  def_curve_quality<Points2Ref>(m, "curve_quality");
  def_curve_quality<PreparedCurve>(m, "prepared_curve_quality");
}
