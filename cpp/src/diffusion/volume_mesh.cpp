// The only translation unit with CGAL's Polyhedral_mesh_domain_3 (it compiles slowly; the shell
// between two surfaces has its own in shell_mesh.cpp).
#include "diffusion/volume_mesh.hpp"

#include "common/validation.hpp"
#include "diffusion/mesh_in_child.hpp"
#include "surfaces/surface_mesh.hpp"

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

#include <algorithm>
#include <array>
#include <map>
#include <set>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

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

// Mesh_3 leaves tetrahedra with all four corners on the surface (caps under curved patches):
// the boundary displacement alone moves them, and where the surface bends they turn over
// whatever the interior does. Each gets a free node: the midpoint of its longest chord (an edge
// between surface nodes on no surface triangle), splitting every tetrahedron round that edge.
void split_chords(VolumeMesh& mesh) {
  const Index n = mesh.vertices.rows();
  std::vector<char> on_surface(n, 0);
  std::set<std::pair<Index, Index>> surface_edges;
  {
    std::map<std::array<Index, 3>, int> faces;
    for (Index t = 0; t < mesh.tetrahedra.rows(); ++t) {
      for (int skip = 0; skip < 4; ++skip) {
        std::array<Index, 3> face;
        for (int i = 0, k = 0; i < 4; ++i) {
          if (i != skip) face[k++] = mesh.tetrahedra(t, i);
        }
        std::sort(face.begin(), face.end());
        ++faces[face];
      }
    }
    for (const auto& [face, count] : faces) {
      if (count != 1) continue;
      for (int i = 0; i < 3; ++i) {
        on_surface[face[i]] = 1;
        surface_edges.emplace(face[i], face[(i + 1) % 3]);
        surface_edges.emplace(face[(i + 1) % 3], face[i]);
      }
    }
  }
  std::set<std::pair<Index, Index>> chords;
  for (Index t = 0; t < mesh.tetrahedra.rows(); ++t) {
    bool all = true;
    for (int i = 0; i < 4; ++i) all = all && on_surface[mesh.tetrahedra(t, i)];
    if (!all) continue;
    std::pair<Index, Index> longest(-1, -1);
    double length = -1.0;
    for (int i = 0; i < 4; ++i) {
      for (int j = i + 1; j < 4; ++j) {
        const Index a = std::min(mesh.tetrahedra(t, i), mesh.tetrahedra(t, j));
        const Index b = std::max(mesh.tetrahedra(t, i), mesh.tetrahedra(t, j));
        const double l = (mesh.vertices.row(a) - mesh.vertices.row(b)).norm();
        if (!surface_edges.count({a, b}) && l > length) {
          length = l;
          longest = {a, b};
        }
      }
    }
    if (longest.first >= 0) chords.insert(longest);
  }
  if (chords.empty()) return;
  // Each tetrahedron with both ends of a chord becomes two, the midpoint in place of one end and
  // then the other (the orientation stays); a chord another split has cut is left.
  std::vector<Eigen::Matrix<Index, 1, 4>> tets;
  for (Index t = 0; t < mesh.tetrahedra.rows(); ++t) tets.push_back(mesh.tetrahedra.row(t));
  // The tetrahedra around each vertex, so that a chord's are found without a scan of the mesh;
  // an entry may be stale (a split took the vertex out of that tetrahedron): checked on use.
  std::vector<std::vector<std::size_t>> around(static_cast<std::size_t>(n) + chords.size());
  for (std::size_t t = 0; t < tets.size(); ++t) {
    for (int i = 0; i < 4; ++i) around[static_cast<std::size_t>(tets[t](i))].push_back(t);
  }
  std::vector<Eigen::RowVector3d> added;
  for (const auto& [a, b] : chords) {
    const Index m = n + static_cast<Index>(added.size());
    bool split = false;
    const std::vector<std::size_t> candidates = around[static_cast<std::size_t>(a)];
    for (const std::size_t t : candidates) {
      int ia = -1, ib = -1;
      for (int i = 0; i < 4; ++i) {
        if (tets[t](i) == a) ia = i;
        if (tets[t](i) == b) ib = i;
      }
      if (ia < 0 || ib < 0) continue;
      Eigen::Matrix<Index, 1, 4> other = tets[t];
      tets[t](ib) = m;
      other(ia) = m;
      tets.push_back(other);
      const std::size_t u = tets.size() - 1;
      around[static_cast<std::size_t>(m)].push_back(t);
      for (int i = 0; i < 4; ++i) around[static_cast<std::size_t>(other(i))].push_back(u);
      split = true;
    }
    if (split) added.push_back(0.5 * (mesh.vertices.row(a) + mesh.vertices.row(b)));
  }
  mesh.vertices.conservativeResize(n + static_cast<Index>(added.size()), 3);
  for (std::size_t k = 0; k < added.size(); ++k) mesh.vertices.row(n + static_cast<Index>(k)) = added[k];
  mesh.tetrahedra.resize(static_cast<Index>(tets.size()), 4);
  for (std::size_t t = 0; t < tets.size(); ++t) mesh.tetrahedra.row(static_cast<Index>(t)) = tets[t];
}

}  // namespace

// `size` arrives resolved and > 0: the mesh_size option is checked where it enters
// (require_mesh_size), the default where it is computed (extend's default_size).
VolumeMesh mesh_volume(const Points3Ref& vertices, const FacesRef& faces, double size, int seed, const char* name) {
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
  VolumeMesh mesh{shell.vertices, shell.tetrahedra};
  split_chords(mesh);
  return mesh;
}

}  // namespace morphomap::detail
