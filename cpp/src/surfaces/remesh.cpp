// Isotropic remeshing of closed surfaces: its own translation unit, as CGAL's mesh processing
// compiles slowly.
#include <morphomap/remesh.hpp>

#include <morphomap/errors.hpp>

#include "common/interrupt_check.hpp"
#include "common/validation.hpp"
#include "surfaces/surface_mesh.hpp"
#include "surfaces/surface_util.hpp"

#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/orientation.h>
#include <CGAL/Polygon_mesh_processing/remesh.h>
#include <CGAL/Polygon_mesh_processing/repair_degeneracies.h>
#include <CGAL/Polygon_mesh_processing/repair_self_intersections.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/boost/graph/helpers.h>

#include <cmath>
#include <string>

namespace morphomap {

namespace PMP = CGAL::Polygon_mesh_processing;

namespace {

void require_input(const Points3Ref& vertices, const FacesRef& faces) {
  if (faces.rows() < 4)
    detail::invalid("surface", "has " + std::to_string(faces.rows()) + " faces: a closed surface needs at least 4");
  if (!vertices.allFinite()) detail::invalid("surface", "has a vertex with a non-finite coordinate");
  detail::require_face_indices(faces, vertices.rows(), "surface");
}

}  // namespace

TriangleSurface remesh_surface(const Points3Ref& vertices, const FacesRef& triangles, double edge_length,
                               int iterations) {
  require_input(vertices, triangles);
  if (!(std::isfinite(edge_length) && edge_length > 0)) {
    detail::invalid("edge_length", "must be a positive finite number, got " + std::to_string(edge_length));
  }
  if (iterations < 1) detail::invalid("iterations", "must be at least 1, got " + std::to_string(iterations));

  detail::SurfaceMesh mesh;
  try {
    mesh = detail::to_surface_mesh(vertices, triangles);
  } catch (const GeometryError&) {
    detail::invalid("surface",
                    "is not a manifold triangle mesh (an edge has more than two faces or a face is repeated)");
  }
  if (!CGAL::is_closed(mesh)) detail::invalid("surface", "is not closed (it has boundary edges)");
  auto component = mesh.add_property_map<detail::SurfaceMesh::Face_index, std::size_t>("f:component", 0).first;
  if (PMP::connected_components(mesh, component) != 1) {
    detail::invalid("surface", "has several connected components: remesh each on its own");
  }
  mesh.remove_property_map(component);
  const bool outward = PMP::is_outward_oriented(mesh);
  // Zero-area faces have no normal for the relaxation to follow.
  PMP::remove_degenerate_faces(mesh);
  mesh.collect_garbage();
  if (!CGAL::is_closed(mesh) || mesh.number_of_faces() < 4) {
    throw GeometryError("surface: removing its zero-area faces left no closed surface");
  }
  detail::check_interrupt();
  // All rounds in one call: each call projects onto the surface it was given, so rounds in
  // separate calls would drift away from the input surface.
  PMP::isotropic_remeshing(faces(mesh), edge_length, mesh, CGAL::parameters::number_of_iterations(iterations));
  detail::check_interrupt();
  // Relaxation and projection onto a staircase of voxels (the terraces of a coarse z spacing)
  // can turn a few triangles over; CGAL repairs such spots locally.
  if (PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(mesh)) {
    PMP::experimental::remove_self_intersections(mesh);
    mesh.collect_garbage();
    if (!CGAL::is_closed(mesh) || PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(mesh)) {
      throw GeometryError("surface: remeshing at edge length " + std::to_string(edge_length) +
                          " makes the surface intersect itself: try a smaller edge_length or smooth the mask");
    }
  }
  detail::check_interrupt();
  mesh.collect_garbage();
  if (PMP::is_outward_oriented(mesh) != outward) PMP::reverse_face_orientations(mesh);

  TriangleSurface out;
  detail::from_surface_mesh(mesh, out.vertices, out.faces);
  return out;
}

}  // namespace morphomap
