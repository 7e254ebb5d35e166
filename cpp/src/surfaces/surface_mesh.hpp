#pragma once
// Our (vertices, faces) arrays as a CGAL Surface_mesh and back: the form CGAL's mesh processing
// and 3D mesher take.
#include <morphomap/errors.hpp>
#include <morphomap/types.hpp>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Surface_mesh.h>

#include <vector>

namespace morphomap::detail {

using SurfaceMesh = CGAL::Surface_mesh<CGAL::Exact_predicates_inexact_constructions_kernel::Point_3>;

// The referenced vertices and the faces (vertices no face uses are left out). Throws
// GeometryError if the faces do not form a manifold triangle mesh.
inline SurfaceMesh to_surface_mesh(const Points3Ref& vertices, const FacesRef& faces) {
  SurfaceMesh mesh;
  std::vector<SurfaceMesh::Vertex_index> handle(vertices.rows());
  std::vector<char> used(vertices.rows(), 0);
  for (Index f = 0; f < faces.rows(); ++f) {
    for (int i = 0; i < 3; ++i) used[faces(f, i)] = 1;
  }
  for (Index v = 0; v < vertices.rows(); ++v) {
    if (used[v]) handle[v] = mesh.add_vertex({vertices(v, 0), vertices(v, 1), vertices(v, 2)});
  }
  for (Index f = 0; f < faces.rows(); ++f) {
    if (mesh.add_face(handle[faces(f, 0)], handle[faces(f, 1)], handle[faces(f, 2)]) == SurfaceMesh::null_face()) {
      throw GeometryError("a surface is not a manifold triangle mesh");
    }
  }
  return mesh;
}

// The vertices in order of their indices (the mesh has no removed elements: collect_garbage()
// was called) and the faces as index triples.
inline void from_surface_mesh(const SurfaceMesh& mesh, Points3& vertices, Faces& faces) {
  vertices.resize(mesh.number_of_vertices(), 3);
  for (const auto v : mesh.vertices()) {
    const auto& p = mesh.point(v);
    vertices.row(Index(v.idx())) << p.x(), p.y(), p.z();
  }
  faces.resize(mesh.number_of_faces(), 3);
  Index row = 0;
  for (const auto f : mesh.faces()) {
    int corner = 0;
    for (const auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) faces(row, corner++) = Index(v.idx());
    ++row;
  }
}

}  // namespace morphomap::detail
