// Bindings of the quality measures of a displacement field.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <morphomap/quality.hpp>

#include "interrupt_guard.hpp"

namespace py = pybind11;
using namespace pybind11::literals;  // results cross as dicts keyed by field name
using namespace morphomap;

void bind_quality(py::module_& m) {
  m.def(
      "curve_quality",
      [](const Points2Ref& starts, const Points2Ref& ends, const Points2Ref& c1, const Points2Ref& c2, bool closed) {
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
