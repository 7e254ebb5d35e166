// The only translation unit with CGAL's Polyhedral_mesh_domain_3 (it compiles slowly; the shell
// between two surfaces has its own in shell_mesh.cpp).
#include "volume_mesh.hpp"

#include "mesh_in_child.hpp"
#include "surface_mesh.hpp"
#include "validation.hpp"

#include <morphomap/errors.hpp>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polyhedral_mesh_domain_3.h>
#include <CGAL/Random.h>
#include <CGAL/boost/graph/helpers.h>
#include <CGAL/make_mesh_3.h>

#include <cmath>
#include <string>
#include <unordered_map>

namespace morphomap::detail {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Domain = CGAL::Polyhedral_mesh_domain_3<SurfaceMesh, Kernel>;
using Triangulation = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Triangulation>;
using Criteria = CGAL::Mesh_criteria_3<Triangulation>;

// The shape of the answer mesh_in_child carries; only vertices and tetrahedra are used.
ShellMesh as_shell_mesh(const C3t3& c3t3) {
  const Triangulation& tr = c3t3.triangulation();
  std::unordered_map<Triangulation::Vertex_handle, Index> vertex_index;
  ShellMesh mesh;
  mesh.tetrahedra.resize(static_cast<Index>(c3t3.number_of_cells_in_complex()), 4);
  Index t = 0;
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c, ++t) {
    for (int i = 0; i < 4; ++i) {
      mesh.tetrahedra(t, i) = vertex_index.emplace(c->vertex(i), static_cast<Index>(vertex_index.size())).first->second;
    }
  }
  if (t == 0) throw GeometryError("meshing the region the surface encloses gave no tetrahedra");
  mesh.vertices.resize(static_cast<Index>(vertex_index.size()), 3);
  for (const auto& [v, k] : vertex_index) {
    const auto p = tr.geom_traits().construct_point_3_object()(v->point());
    mesh.vertices.row(k) << p.x(), p.y(), p.z();
  }
  mesh.neighbours = Tetrahedra::Constant(t, 4, -1);
  mesh.patches.setConstant(t, 4, other_face);
  return mesh;
}

}  // namespace

VolumeMesh mesh_volume(const Points3Ref& vertices, const FacesRef& faces, double size, int seed, const char* name) {
  if (!(size > 0.0) || !std::isfinite(size)) invalid("mesh_size", "must be a finite number > 0");
  SurfaceMesh surface;
  try {
    surface = to_surface_mesh(vertices, faces);
  } catch (const GeometryError&) {
    invalid(name, "its triangles are not a manifold surface");
  }
  if (!CGAL::is_closed(surface)) invalid(name, "its triangles do not close a volume (pass the solver's mesh=)");
  // Mesh_3 on a self-intersecting surface may crash rather than fail.
  if (CGAL::Polygon_mesh_processing::does_self_intersect(surface)) invalid(name, "its surface intersects itself");
  const ShellMesh shell = mesh_in_child(
      [&] {
        try {
          CGAL::Random random(seed);
          const Domain domain(surface, &random);
          namespace params = CGAL::parameters;
          const Criteria criteria(params::facet_angle = 25.0, params::facet_size = size,
                                  params::facet_distance = 0.1 * size, params::cell_radius_edge_ratio = 3.0,
                                  params::cell_size = size);
          // No perturbation (it moves vertices at random) and no exudation (its result changes from run
          // to run): the same surface and seed give the same mesh.
          return as_shell_mesh(CGAL::make_mesh_3<C3t3>(domain, criteria, params::no_perturb(), params::no_exude()));
        } catch (const CGAL::Failure_exception& e) {
          throw GeometryError(std::string("meshing the region the surface encloses failed: ") + e.what());
        }
      },
      "meshing the region the surface encloses");
  return {shell.vertices, shell.tetrahedra};
}

}  // namespace morphomap::detail
