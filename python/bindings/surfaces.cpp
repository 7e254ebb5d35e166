// Bindings of the 3D surface kernels: SurfaceIndex, vertex normals, map_surfaces and quality.
#include <pybind11/eigen.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <morphomap/errors.hpp>
#include <morphomap/prepared_surface.hpp>
#include <morphomap/quality.hpp>
#include <morphomap/remesh.hpp>
#include <morphomap/surface_mapping.hpp>
#include <morphomap/surface_queries.hpp>

#include "methods.hpp"

#include "interrupt_guard.hpp"
#include "stage_callback.hpp"

#include <memory>
#include <string>

namespace py = pybind11;
using namespace pybind11::literals;  // results cross as dicts keyed by field name
using namespace morphomap;

namespace {

using Release = py::call_guard<py::gil_scoped_release>;

py::dict hits_record(SurfaceHits&& h) {
  return py::dict("points"_a = std::move(h.points), "distances"_a = std::move(h.distances),
                  "faces"_a = std::move(h.faces));
}

}  // namespace

void bind_surfaces(py::module_& m) {
  py::class_<SurfaceIndex>(m, "SurfaceIndex")
      .def(py::init<const Points3Ref&, const FacesRef&>(), py::arg("vertices"), py::arg("faces"), Release())
      .def(
          "closest_points",
          [](const SurfaceIndex& index, const Points3Ref& queries) {
            SurfaceHits hits;
            {
              py::gil_scoped_release release;
              hits = index.closest_points(queries);
            }
            return hits_record(std::move(hits));
          },
          py::arg("queries"))
      .def(
          "line_intersections",
          [](const SurfaceIndex& index, const Points3Ref& origins, const Points3Ref& directions) {
            SurfaceHits hits;
            {
              py::gil_scoped_release release;
              hits = index.line_intersections(origins, directions);
            }
            return hits_record(std::move(hits));
          },
          py::arg("origins"), py::arg("directions"));

  py::class_<PreparedSurface>(m, "PreparedSurface")
      .def(py::init([](const Points3Ref& vertices, const FacesRef& faces, const std::string& name) {
             py::gil_scoped_release release;
             return std::make_unique<PreparedSurface>(vertices, faces, name.c_str());
           }),
           py::arg("vertices"), py::arg("faces"), py::arg("name"));

  m.def("vertex_normals", &vertex_normals, py::arg("vertices"), py::arg("faces"), Release());
  m.def(
      "check_closed_surface",
      [](const Points3Ref& vertices, const FacesRef& faces, const std::string& name) {
        py::gil_scoped_release release;
        return check_closed_surface(vertices, faces, name.c_str());
      },
      py::arg("vertices"), py::arg("faces"), py::arg("name"));

  m.def(
      "map_surfaces",
      [](const Points3Ref& v1, const FacesRef& f1, const Points3Ref& v2, const FacesRef& f2, const std::string& method,
         bool reverse, double mesh_size, bool repeatable, const py::object& on_stage) {
        SurfaceMappingOptions options;
        options.method = map_method_named(method);
        options.reverse = reverse;
        options.diffusion_mesh_size = mesh_size;
        options.diffusion_repeatable = repeatable;
        options.on_stage = stage_callback(on_stage);
        DisplacementField3 field;
        InterruptGuard interruptible;
        {
          py::gil_scoped_release release;
          field = map_surfaces(v1, f1, v2, f2, options);
        }
        return field_record(std::move(field));
      },
      py::arg("v1"), py::arg("f1"), py::arg("v2"), py::arg("f2"), py::arg("method"), py::arg("reverse"),
      py::arg("mesh_size"), py::arg("repeatable"), py::arg("on_stage") = py::none());

  m.def(
      "map_prepared_surfaces",
      [](const PreparedSurface& s1, const PreparedSurface& s2, const std::string& method, bool reverse,
         double mesh_size, bool repeatable, const py::object& on_stage) {
        SurfaceMappingOptions options;
        options.method = map_method_named(method);
        options.reverse = reverse;
        options.diffusion_mesh_size = mesh_size;
        options.diffusion_repeatable = repeatable;
        options.on_stage = stage_callback(on_stage);
        DisplacementField3 field;
        InterruptGuard interruptible;
        {
          py::gil_scoped_release release;
          field = map_surfaces(s1, s2, options);
        }
        return field_record(std::move(field));
      },
      py::arg("s1"), py::arg("s2"), py::arg("method"), py::arg("reverse"), py::arg("mesh_size"), py::arg("repeatable"),
      py::arg("on_stage") = py::none());
  m.def(
      "prepared_surface_quality",
      [](const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces, const PreparedSurface& s1,
         const PreparedSurface& s2) {
        SurfaceQuality q;
        InterruptGuard interruptible;
        {
          py::gil_scoped_release release;
          DisplacementField3 field{starts, ends, faces, {}};
          q = quality(field, s1, s2);
        }
        return py::dict("qm1"_a = q.qm1, "qm2"_a = q.qm2, "qm"_a = q.qm, "folds"_a = q.folds);
      },
      py::arg("starts"), py::arg("ends"), py::arg("faces"), py::arg("s1"), py::arg("s2"));
  m.def(
      "surface_quality",
      [](const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces, const Points3Ref& v1,
         const FacesRef& f1, const Points3Ref& v2, const FacesRef& f2) {
        SurfaceQuality q;
        InterruptGuard interruptible;
        {
          py::gil_scoped_release release;
          DisplacementField3 field{starts, ends, faces, {}};
          q = quality(field, v1, f1, v2, f2);
        }
        return py::dict("qm1"_a = q.qm1, "qm2"_a = q.qm2, "qm"_a = q.qm, "folds"_a = q.folds);
      },
      py::arg("starts"), py::arg("ends"), py::arg("faces"), py::arg("v1"), py::arg("f1"), py::arg("v2"), py::arg("f2"));
  m.def(
      "count_folds",
      [](const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces, const Points3Ref& v1,
         const FacesRef& f1, const Points3Ref& v2,
         const FacesRef& f2) { return count_folds(starts, ends, faces, v1, f1, v2, f2); },
      py::arg("starts"), py::arg("ends"), py::arg("faces"), py::arg("v1"), py::arg("f1"), py::arg("v2"), py::arg("f2"),
      Release());

  m.def(
      "remesh_surface",
      [](const Points3Ref& vertices, const FacesRef& faces, double edge_length, int iterations) {
        TriangleSurface surface;
        InterruptGuard interruptible;
        {
          py::gil_scoped_release release;
          surface = remesh_surface(vertices, faces, edge_length, iterations);
        }
        return py::dict("vertices"_a = std::move(surface.vertices), "faces"_a = std::move(surface.faces));
      },
      py::arg("vertices"), py::arg("faces"), py::arg("edge_length"), py::arg("iterations"));
}
