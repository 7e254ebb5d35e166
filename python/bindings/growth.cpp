// Bindings of the growth kinematics per segment (2D) or triangle (3D).
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>

#include <morphomap/growth.hpp>

namespace py = pybind11;
using namespace pybind11::literals;  // results cross as dicts keyed by field name
using namespace morphomap;

void bind_growth(py::module_& m) {
  m.def(
      "curve_growth",
      [](const Points2Ref& before, const Points2Ref& after, const SegmentsRef& segments, double dt,
         bool counter_clockwise) {
        CurveGrowth g;
        {
          py::gil_scoped_release release;
          g = curve_growth(before, after, segments, dt, counter_clockwise);
        }
        return py::dict("stretch"_a = std::move(g.stretch), "direction"_a = std::move(g.direction),
                        "normal_velocity"_a = std::move(g.normal_velocity),
                        "tangential_velocity"_a = std::move(g.tangential_velocity));
      },
      py::arg("before"), py::arg("after"), py::arg("segments"), py::arg("dt"), py::arg("counter_clockwise"));
  m.def(
      "surface_growth",
      [](const Points3Ref& before, const Points3Ref& after, const FacesRef& faces, double dt) {
        SurfaceGrowth g;
        {
          py::gil_scoped_release release;
          g = surface_growth(before, after, faces, dt);
        }
        return py::dict("stretches"_a = std::move(g.stretches), "major"_a = std::move(g.major),
                        "minor"_a = std::move(g.minor), "normal_velocity"_a = std::move(g.normal_velocity),
                        "tangential_velocity"_a = std::move(g.tangential_velocity));
      },
      py::arg("before"), py::arg("after"), py::arg("faces"), py::arg("dt"));
}
