// Isotropic remeshing of closed surfaces: its own translation unit, as CGAL's mesh processing
// compiles slowly.
#include <morphomap/remesh.hpp>

#include <morphomap/errors.hpp>

#include "common/interrupt_check.hpp"
#include "common/validation.hpp"
#include "surfaces/refine.hpp"
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
#include <vector>

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

bool detail::has_poor_triangles(const Points3Ref& vertices, const FacesRef& faces) {
  const double limit = std::cos(kPoorAngleDegrees * 3.14159265358979323846 / 180.0);
  for (Index k = 0; k < faces.rows(); ++k) {
    for (int j = 0; j < 3; ++j) {
      const Eigen::RowVector3d corner = vertices.row(faces(k, j));
      const Eigen::RowVector3d a = vertices.row(faces(k, (j + 1) % 3)) - corner;
      const Eigen::RowVector3d b = vertices.row(faces(k, (j + 2) % 3)) - corner;
      const double na = a.norm(), nb = b.norm();
      if (na > 0.0 && nb > 0.0 && a.dot(b) / (na * nb) > limit) return true;
    }
  }
  return false;
}

TriangleSurface detail::refined_keeping_vertices(const Points3Ref& vertices, const FacesRef& faces,
                                                 double edge_length) {
  detail::SurfaceMesh mesh = detail::to_surface_mesh(vertices, faces);
  using Vertex = detail::SurfaceMesh::Vertex_index;
  auto kept = mesh.add_property_map<Vertex, bool>("v:kept", false).first;
  auto original = mesh.add_property_map<Vertex, Index>("v:original", -1).first;
  // to_surface_mesh adds the vertices that faces use, in their order.
  const Index count = vertices.rows();
  std::vector<char> used(static_cast<std::size_t>(count), 0);
  for (Index k = 0; k < faces.rows(); ++k) {
    for (int j = 0; j < 3; ++j) used[static_cast<std::size_t>(faces(k, j))] = 1;
  }
  Index input_row = 0;
  for (const Vertex v : mesh.vertices()) {
    while (!used[static_cast<std::size_t>(input_row)]) ++input_row;
    kept[v] = true;
    original[v] = input_row++;
  }
  // Three rounds, as surface_from_mask's (REMESH_ROUNDS), in one call (see remesh_surface).
  PMP::isotropic_remeshing(CGAL::faces(mesh), edge_length, mesh,
                           CGAL::parameters::number_of_iterations(3).vertex_is_constrained_map(kept));
  detail::check_interrupt();
  if (PMP::does_self_intersect<CGAL::Parallel_if_available_tag>(mesh)) {
    throw GeometryError("surface: refining its triangles at edge length " + std::to_string(edge_length) +
                        " makes it intersect itself");
  }
  mesh.collect_garbage();
  TriangleSurface out;
  Index unused = 0;
  for (const char u : used) unused += u ? 0 : 1;
  out.vertices.resize(static_cast<Index>(mesh.number_of_vertices()) + unused, 3);
  out.vertices.topRows(count) = vertices;  // the unused rows too
  std::vector<Index> row(mesh.num_vertices(), -1);
  Index next = count;
  for (const Vertex v : mesh.vertices()) {
    const Index r = original[v] >= 0 ? original[v] : next++;
    row[v.idx()] = r;
    const auto& p = mesh.point(v);
    out.vertices.row(r) << p.x(), p.y(), p.z();
  }
  if (next != out.vertices.rows()) throw GeometryError("surface: refining its triangles lost one of its vertices");
  out.faces.resize(static_cast<Index>(mesh.number_of_faces()), 3);
  Index k = 0;
  for (const auto f : mesh.faces()) {
    int j = 0;
    for (const Vertex v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) out.faces(k, j++) = row[v.idx()];
    ++k;
  }
  return out;
}

}  // namespace morphomap
