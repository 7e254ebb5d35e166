// The only translation unit with CGAL's 3D mesher (it compiles slowly): the shell between two
// nested closed surfaces, meshed as a polyhedral complex whose two patches separate the shell
// (subdomain 1) from the outside (subdomain 0).
#include "shell_mesh.hpp"

#include <morphomap/errors.hpp>

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polygon_mesh_processing/intersection.h>
#include <CGAL/Polyhedral_complex_mesh_domain_3.h>
#include <CGAL/Orthogonal_k_neighbor_search.h>
#include <CGAL/Random.h>
#include <CGAL/Search_traits_3.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/properties_Surface_mesh_features.h>
#include <CGAL/refine_mesh_3.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

namespace morphomap::detail {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using SurfaceMesh = CGAL::Surface_mesh<Point>;
using Domain = CGAL::Polyhedral_complex_mesh_domain_3<Kernel, SurfaceMesh>;
using Triangulation = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Triangulation, Domain::Corner_index, Domain::Curve_index>;
using Criteria = CGAL::Mesh_criteria_3<Triangulation>;

using SearchTraits = CGAL::Search_traits_3<Kernel>;
using Neighbour = CGAL::Orthogonal_k_neighbor_search<SearchTraits>;
using PointTree = Neighbour::Tree;
using Triangles = std::vector<Kernel::Triangle_3>;
using SoupTree =
    CGAL::AABB_tree<CGAL::AABB_traits<Kernel, CGAL::AABB_triangle_primitive<Kernel, Triangles::const_iterator>>>;

// The referenced vertices and the faces as a Surface_mesh (the caller checked that it is closed).
SurfaceMesh to_surface_mesh(const Points3Ref& vertices, const FacesRef& faces) {
  SurfaceMesh mesh;
  std::vector<SurfaceMesh::Vertex_index> handle(vertices.rows());
  std::vector<char> used(vertices.rows(), 0);
  for (Index f = 0; f < faces.rows(); ++f) {
    for (int i = 0; i < 3; ++i) used[faces(f, i)] = 1;
  }
  for (Index v = 0; v < vertices.rows(); ++v) {
    if (used[v]) handle[v] = mesh.add_vertex(Point(vertices(v, 0), vertices(v, 1), vertices(v, 2)));
  }
  for (Index f = 0; f < faces.rows(); ++f) {
    if (mesh.add_face(handle[faces(f, 0)], handle[faces(f, 1)], handle[faces(f, 2)]) ==
        SurfaceMesh::null_face()) {
      throw GeometryError("a surface is not a manifold triangle mesh");
    }
  }
  return mesh;
}

// Target edge length at a point: graded from the size at each surface with the distance to it,
// the distance estimated by the nearest surface vertex (cheap: Mesh_3 asks very often). Mesh_3
// copies its sizing fields: the trees are shared.
class Sizing {
 public:
  Sizing(const SurfaceMesh& source, const SurfaceMesh& target, const ShellMeshCriteria& criteria)
      : source_(std::make_shared<PointTree>(source.points().begin(), source.points().end())),
        target_(std::make_shared<PointTree>(target.points().begin(), target.points().end())),
        criteria_(criteria) {
    source_->build();
    target_->build();
  }

  template <typename Index_>
  double operator()(const Point& p, int, const Index_&) const {
    const double ds = std::sqrt(Neighbour(*source_, p, 1).begin()->second);
    const double dt = std::sqrt(Neighbour(*target_, p, 1).begin()->second);
    return std::min({criteria_.cell_size, criteria_.source_size + criteria_.grading * ds,
                     criteria_.target_size + criteria_.grading * dt});
  }

 private:
  std::shared_ptr<PointTree> source_, target_;
  ShellMeshCriteria criteria_;
};

}  // namespace

Nesting classify_nesting(const Points3Ref& source_vertices, const FacesRef& source_faces,
                         const Points3Ref& target_vertices, const FacesRef& target_faces) {
  try {
    const SurfaceMesh source = to_surface_mesh(source_vertices, source_faces);
    const SurfaceMesh target = to_surface_mesh(target_vertices, target_faces);
    if (CGAL::Polygon_mesh_processing::do_intersect(source, target)) return Nesting::crossing;
    const CGAL::Side_of_triangle_mesh<SurfaceMesh, Kernel> in_target(target), in_source(source);
    const Point s = source.point(*source.vertices().begin());
    const Point t = target.point(*target.vertices().begin());
    if (in_target(s) == CGAL::ON_BOUNDED_SIDE) return Nesting::source_inside;
    if (in_source(t) == CGAL::ON_BOUNDED_SIDE) return Nesting::target_inside;
    return Nesting::disjoint;
  } catch (const CGAL::Failure_exception& e) {
    throw GeometryError(std::string("comparing the two surfaces failed: ") + e.what());
  }
}

ShellMesh mesh_shell(const Points3Ref& source_vertices, const FacesRef& source_faces,
                     const Points3Ref& target_vertices, const FacesRef& target_faces, bool source_inside,
                     const ShellMeshCriteria& criteria) {
  C3t3 c3t3;
  try {
    std::vector<SurfaceMesh> patches{to_surface_mesh(source_vertices, source_faces),
                                     to_surface_mesh(target_vertices, target_faces)};
    // (subdomain inside, subdomain outside) of each outward-oriented patch; the shell is 1.
    const std::pair<int, int> inner(0, 1), outer(1, 0);
    const std::pair<int, int> sides[2] = {source_inside ? inner : outer, source_inside ? outer : inner};
    const Sizing sizing(patches[0], patches[1], criteria);
    CGAL::Random random(0);
    const Domain domain(patches.begin(), patches.end(), sides, sides + 2, &random);
    namespace params = CGAL::parameters;
    const Criteria mesh_criteria(params::facet_angle = 25.0, params::facet_size = sizing,
                                 params::facet_distance = criteria.facet_distance,
                                 params::cell_radius_edge_ratio = 3.0, params::cell_size = sizing);
    // Mesh_3's own initial points come from rays shot from the centre of the bounding box and may
    // all land on the outer surface, so that the inner one is never found: start instead from a
    // few vertices of each surface, as points of its patch.
    // (Asking for the construction object makes the domain detect its borders, as make_mesh_3 would.)
    (void)domain.construct_initial_points_object();
    Triangulation& tr = c3t3.triangulation();
    const auto weighted = tr.geom_traits().construct_weighted_point_3_object();
    for (int patch = 1; patch <= 2; ++patch) {
      const SurfaceMesh& surface = patches[patch - 1];
      const std::size_t n = surface.number_of_vertices(), stride = std::max<std::size_t>(1, n / 20);
      std::size_t k = 0;
      for (const auto v : surface.vertices()) {
        if (k++ % stride != 0) continue;
        const auto handle = tr.insert(weighted(surface.point(v)));
        if (handle == Triangulation::Vertex_handle()) continue;
        c3t3.set_dimension(handle, 2);
        c3t3.set_index(handle, domain.index_from_surface_patch_index(patch));
      }
    }
    if (criteria.exude) {
      CGAL::refine_mesh_3(c3t3, domain, mesh_criteria, params::no_perturb(), params::exude());
    } else {
      CGAL::refine_mesh_3(c3t3, domain, mesh_criteria, params::no_perturb(), params::no_exude());
    }
  } catch (const CGAL::Failure_exception& e) {
    throw GeometryError(std::string("meshing the region between the surfaces failed: ") + e.what());
  }

  ShellMesh mesh;
  const Triangulation& tr = c3t3.triangulation();
  std::unordered_map<Triangulation::Cell_handle, Index> cell_index;
  std::unordered_map<Triangulation::Vertex_handle, Index> vertex_index;
  Index cells = 0;
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c) {
    cell_index[c] = cells++;
    for (int i = 0; i < 4; ++i) vertex_index.emplace(c->vertex(i), static_cast<Index>(vertex_index.size()));
  }
  if (cells == 0) throw GeometryError("meshing the region between the surfaces gave no tetrahedra");
  mesh.vertices.resize(static_cast<Index>(vertex_index.size()), 3);
  for (const auto& [v, k] : vertex_index) {
    const Point p = tr.geom_traits().construct_point_3_object()(v->point());
    mesh.vertices.row(k) << p.x(), p.y(), p.z();
  }
  mesh.tetrahedra.resize(cells, 4);
  mesh.neighbours.resize(cells, 4);
  mesh.patches.resize(cells, 4);
  for (const auto& [c, t] : cell_index) {
    for (int i = 0; i < 4; ++i) {
      mesh.tetrahedra(t, i) = vertex_index.at(c->vertex(i));
      const auto across = cell_index.find(c->neighbor(i));
      if (across != cell_index.end()) {
        mesh.neighbours(t, i) = across->second;
        mesh.patches(t, i) = interior_face;
      } else {
        mesh.neighbours(t, i) = -1;
        const int patch = c3t3.is_in_complex(c, i) ? static_cast<int>(c3t3.surface_patch_index(c, i)) : -1;
        mesh.patches(t, i) = patch == 1 ? source_face : patch == 2 ? target_face : other_face;
      }
    }
  }
  return mesh;
}

TriangleHits closest_on_triangles(const Points3Ref& vertices, const FacesRef& faces, const Points3Ref& queries) {
  Triangles triangles;
  triangles.reserve(faces.rows());
  auto point = [&](Index v) { return Point(vertices(v, 0), vertices(v, 1), vertices(v, 2)); };
  for (Index f = 0; f < faces.rows(); ++f) {
    triangles.emplace_back(point(faces(f, 0)), point(faces(f, 1)), point(faces(f, 2)));
  }
  TriangleHits hits;
  hits.points.resize(queries.rows(), 3);
  hits.faces.resize(queries.rows());
  try {
    SoupTree tree(triangles.cbegin(), triangles.cend());
    tree.accelerate_distance_queries();
    tbb::parallel_for(Index(0), Index(queries.rows()), [&](Index i) {
      const auto [p, id] = tree.closest_point_and_primitive(Point(queries(i, 0), queries(i, 1), queries(i, 2)));
      hits.points.row(i) << p.x(), p.y(), p.z();
      hits.faces[i] = static_cast<Index>(id - triangles.cbegin());
    });
  } catch (const CGAL::Failure_exception& e) {
    throw GeometryError(std::string("closest points on a surface failed: ") + e.what());
  }
  return hits;
}

}  // namespace morphomap::detail
