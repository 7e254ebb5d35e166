// Bindings of the 2D mapping: map_curves with its options (on plain or prepared curves), and the
// diffusion solution.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <morphomap/errors.hpp>
#include <morphomap/laplace.hpp>
#include <morphomap/mapping.hpp>
#include <morphomap/prepared_curve.hpp>

#include "methods.hpp"

#include "interrupt_guard.hpp"

#include <memory>
#include <optional>
#include <string>

namespace py = pybind11;
using namespace morphomap;

namespace {

CurveMappingOptions curve_mapping_options(const std::string& method, bool closed, Index n, bool reverse, bool transform,
                                          bool split, std::optional<Vec2> anchor, double density_threshold,
                                          double contact_tolerance, double mesh_size, double mesh_fraction,
                                          double stretch_weight) {
  CurveMappingOptions options;
  options.method = map_method_named(method);
  options.closed = closed;
  options.n = n;
  options.reverse = reverse;
  options.transform = transform;
  options.split = split;
  options.anchor = anchor;
  options.density_threshold = density_threshold;
  options.contact_tolerance = contact_tolerance;
  options.diffusion.mesh_size = mesh_size;
  options.diffusion.mesh_fraction = mesh_fraction;
  options.stretch_weight = stretch_weight;
  return options;
}

// map_curves on plain (Points2Ref) or prepared curves, bound under `name` with the same options.
template <class Curve>
void def_map_curves(py::module_& m, const char* name) {
  m.def(
      name,
      [](const Curve& c1, const Curve& c2, const std::string& method, bool closed, Index n, bool reverse,
         bool transform, bool split, std::optional<Vec2> anchor, double density_threshold, double contact_tolerance,
         double mesh_size, double mesh_fraction, double stretch_weight) {
        const CurveMappingOptions options =
            curve_mapping_options(method, closed, n, reverse, transform, split, anchor, density_threshold,
                                  contact_tolerance, mesh_size, mesh_fraction, stretch_weight);
        DisplacementField2 field;
        InterruptGuard interruptible;
        {
          py::gil_scoped_release release;
          field = map_curves(c1, c2, options);
        }
        return field_record(std::move(field));
      },
      py::arg("c1"), py::arg("c2"), py::arg("method"), py::arg("closed"), py::arg("n"), py::arg("reverse"),
      py::arg("transform"), py::arg("split"), py::arg("anchor"), py::arg("density_threshold"),
      py::arg("contact_tolerance"), py::arg("mesh_size"), py::arg("mesh_fraction"),
      py::arg("stretch_weight") = kDefaultStretchWeight);
}

}  // namespace

void bind_mapping(py::module_& m) {
  py::class_<PreparedCurve>(m, "PreparedCurve")
      .def(py::init([](const Points2Ref& points, bool closed, const std::string& name) {
             py::gil_scoped_release release;
             return std::make_unique<PreparedCurve>(points, closed, name.c_str());
           }),
           py::arg("points"), py::arg("closed"), py::arg("name"));
  def_map_curves<Points2Ref>(m, "map_curves");
  def_map_curves<PreparedCurve>(m, "map_prepared_curves");
  // map_curves' checks of its options alone (method "best" makes them before running candidates).
  m.def(
      "validate_options",
      [](bool closed, Index n, std::optional<Vec2> anchor, double density_threshold, double contact_tolerance,
         double mesh_size, double mesh_fraction, double stretch_weight) {
        validate_options(curve_mapping_options("auto", closed, n, false, false, true, anchor, density_threshold,
                                               contact_tolerance, mesh_size, mesh_fraction, stretch_weight));
      },
      py::arg("closed"), py::arg("n"), py::arg("anchor"), py::arg("density_threshold"), py::arg("contact_tolerance"),
      py::arg("mesh_size"), py::arg("mesh_fraction"), py::arg("stretch_weight"));
  m.attr("DEFAULT_STRETCH_WEIGHT") = kDefaultStretchWeight;
  // The core's method table, row by row (read-only views of kMethodTable): the subsets of methods
  // that Python lists are read from it. MAP_METHODS: the names map_curves takes; METHOD_NAMES:
  // what a field's method codes say.
  const auto label = [](const std::optional<Method>& method) -> py::object {
    return method ? py::object(py::str(method_name(*method))) : py::object(py::none());
  };
  py::class_<MethodRow>(m, "MethodRow")
      .def_readonly("name", &MethodRow::name)
      .def_property_readonly("forward", [label](const MethodRow& row) { return label(row.forward); })
      .def_property_readonly("backward", [label](const MethodRow& row) { return label(row.backward); })
      .def_property_readonly("basic", &MethodRow::basic)
      .def_readonly("from_paper", &MethodRow::from_paper)
      .def_readonly("curves", &MethodRow::curves)
      .def_readonly("surfaces", &MethodRow::surfaces)
      .def("__repr__", [](const MethodRow& row) { return std::string("<MethodRow '") + row.name + "'>"; });
  py::list rows, map_methods;
  for (const MethodRow& row : kMethodTable) {
    rows.append(py::cast(&row, py::return_value_policy::reference));
    if (row.curves) map_methods.append(row.name);
  }
  m.attr("METHODS") = py::tuple(rows);
  m.attr("MAP_METHODS") = py::tuple(map_methods);
  py::tuple method_names(kMethodCount);
  for (int code = 0; code < kMethodCount; ++code) method_names[code] = method_name(static_cast<Method>(code));
  m.attr("METHOD_NAMES") = method_names;

  py::class_<CurvePiece>(m, "CurvePiece")
      .def_readonly("source", &CurvePiece::source)
      .def_readonly("target", &CurvePiece::target)
      .def_readonly("begin_meeting", &CurvePiece::begin_meeting)
      .def_readonly("end_meeting", &CurvePiece::end_meeting)
      .def_readonly("source_begin", &CurvePiece::source_begin)
      .def_readonly("source_length", &CurvePiece::source_length)
      .def_readonly("target_begin", &CurvePiece::target_begin)
      .def_readonly("target_length", &CurvePiece::target_length);
  py::class_<CurveSplit>(m, "CurveSplit")
      .def_readonly("pieces", &CurveSplit::pieces)
      .def_readonly("closed", &CurveSplit::closed)
      .def_readonly("direction", &CurveSplit::direction);
  m.def(
      "split_curves",
      [](const Points2Ref& c1, const Points2Ref& c2, bool closed, bool split, double contact_tolerance) {
        py::gil_scoped_release release;
        return split_curves(c1, c2, closed, split, contact_tolerance);
      },
      py::arg("c1"), py::arg("c2"), py::arg("closed"), py::arg("split"), py::arg("contact_tolerance"));
  m.def(
      "piece_labels",
      [](const CurveSplit& split, const Points2Ref& points, bool on_c1) {
        PieceLabels labels;
        {
          py::gil_scoped_release release;
          labels = piece_labels(split, points, on_c1);
        }
        return py::dict(py::arg("piece") = py::cast(labels.piece), py::arg("along") = std::move(labels.along));
      },
      py::arg("split"), py::arg("points"), py::arg("on_c1"));

  m.def(
      "solve_diffusion",
      [](const Points2Ref& source, const Points2Ref& target, bool closed, double mesh_size, double mesh_fraction,
         bool keep_streamlines) {
        DiffusionOptions options;
        options.mesh_size = mesh_size;
        options.mesh_fraction = mesh_fraction;
        options.keep_streamlines = keep_streamlines;
        DiffusionSolution solution;
        InterruptGuard interruptible;
        {
          py::gil_scoped_release release;
          solution = solve_diffusion(source, target, closed, options);
        }
        py::list streamlines;
        for (Points2& line : solution.streamlines) streamlines.append(py::cast(std::move(line)));
        py::dict seconds(py::arg("mesh") = solution.mesh_seconds, py::arg("solve") = solution.solve_seconds,
                         py::arg("trace") = solution.trace_seconds);
        return py::dict(
            py::arg("vertices") = std::move(solution.vertices), py::arg("triangles") = std::move(solution.triangles),
            py::arg("potential") = std::move(solution.potential), py::arg("ends") = std::move(solution.ends),
            py::arg("streamlines") = streamlines, py::arg("seconds") = seconds);
      },
      py::arg("source"), py::arg("target"), py::arg("closed"), py::arg("mesh_size"), py::arg("mesh_fraction"),
      py::arg("keep_streamlines"));
}
