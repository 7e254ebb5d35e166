// Bindings of the 2D curve kernels: resampling, geometry, queries, intersections, crossings.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <morphomap/crossings.hpp>
#include <morphomap/curve_geometry.hpp>
#include <morphomap/curve_queries.hpp>
#include <morphomap/errors.hpp>
#include <morphomap/resample.hpp>

namespace py = pybind11;
using namespace pybind11::literals;  // results cross as dicts keyed by field name
using namespace morphomap;

namespace {

using Release = py::call_guard<py::gil_scoped_release>;

ResampleMethod resample_method(const std::string& name) {
  if (name == "linear") return ResampleMethod::linear;
  if (name == "spline") return ResampleMethod::spline;
  if (name == "pchip") return ResampleMethod::pchip;
  throw morphomap::InvalidInput("method: expected 'linear', 'spline' or 'pchip', got '" + name + "'");
}

py::dict hits_record(CurveHits&& h) {
  return py::dict("points"_a = std::move(h.points), "distances"_a = std::move(h.distances),
                  "segments"_a = std::move(h.segments), "arc_lengths"_a = std::move(h.arc_lengths));
}

}  // namespace

void bind_curves(py::module_& m) {
  m.def(
      "resample",
      [](const Points2Ref& points, Index n, bool closed, const std::string& method) {
        const ResampleMethod kind = resample_method(method);
        py::gil_scoped_release release;
        return resample(points, n, closed, kind);
      },
      py::arg("points"), py::arg("n"), py::arg("closed"), py::arg("method"));

  m.def("arc_lengths", &arc_lengths, py::arg("points"), py::arg("closed"), Release());
  m.def("perimeter", &perimeter, py::arg("points"), py::arg("closed"), Release());
  m.def("signed_area", &signed_area, py::arg("points"), Release());
  m.def("orientation", &orientation, py::arg("points"), Release());
  m.def("normals", &normals, py::arg("points"), py::arg("closed"), Release());
  m.def("is_self_intersecting", &is_self_intersecting, py::arg("points"), py::arg("closed"), Release());

  py::class_<CurveIndex>(m, "CurveIndex")
      .def(py::init<const Points2Ref&, bool>(), py::arg("curve"), py::arg("closed"), Release())
      .def_property_readonly("size", &CurveIndex::size)
      .def_property_readonly("closed", &CurveIndex::closed)
      .def(
          "closest_points",
          [](const CurveIndex& index, const Points2Ref& queries) {
            CurveHits hits;
            {
              py::gil_scoped_release release;
              hits = index.closest_points(queries);
            }
            return hits_record(std::move(hits));
          },
          py::arg("queries"))
      .def(
          "line_intersections",
          [](const CurveIndex& index, const Points2Ref& origins, const Points2Ref& directions) {
            CurveHits hits;
            {
              py::gil_scoped_release release;
              hits = index.line_intersections(origins, directions);
            }
            return hits_record(std::move(hits));
          },
          py::arg("origins"), py::arg("directions"));

  m.def(
      "curve_intersections",
      [](const Points2Ref& c1, const Points2Ref& c2, bool closed) {
        CurveIntersections found;
        {
          py::gil_scoped_release release;
          found = curve_intersections(c1, c2, closed);
        }
        return py::dict("points"_a = std::move(found.points), "arc_lengths1"_a = std::move(found.arc_lengths1),
                        "arc_lengths2"_a = std::move(found.arc_lengths2), "segments1"_a = std::move(found.segments1),
                        "segments2"_a = std::move(found.segments2));
      },
      py::arg("c1"), py::arg("c2"), py::arg("closed"));

  m.def(
      "crossing_pairs",
      [](const Points2Ref& starts, const Points2Ref& ends) {
        std::vector<std::pair<Index, Index>> pairs;
        {
          py::gil_scoped_release release;
          pairs = crossing_pairs(starts, ends);
        }
        Eigen::Matrix<Index, Eigen::Dynamic, 2, Eigen::RowMajor> out(pairs.size(), 2);
        for (std::size_t k = 0; k < pairs.size(); ++k) out(k, 0) = pairs[k].first, out(k, 1) = pairs[k].second;
        return out;
      },
      py::arg("starts"), py::arg("ends"));
  m.def("count_crossings", &count_crossings, py::arg("starts"), py::arg("ends"), Release());
}
