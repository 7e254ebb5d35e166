// The only translation unit with CGAL's 3D mesher (it compiles slowly): the region between two
// closed surfaces, meshed as a polyhedral complex whose patches separate it (subdomains 1 and 2)
// from the rest of space (subdomain 0). Nested surfaces give one shell with two patches; crossing
// surfaces are first cut where they cross.
#include "diffusion/shell_mesh.hpp"

#include "common/nearest_point.hpp"
#include "common/run_both.hpp"
#include "surfaces/surface_mesh.hpp"

#include <morphomap/errors.hpp>

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polygon_mesh_processing/bbox.h>
#include <CGAL/Polygon_mesh_processing/connected_components.h>
#include <CGAL/Polygon_mesh_processing/corefinement.h>
#include <CGAL/Polygon_mesh_processing/intersection.h>
#include <CGAL/Polygon_mesh_processing/self_intersections.h>
#include <CGAL/Polyhedral_complex_mesh_domain_3.h>
#include <CGAL/Random.h>
#include <CGAL/Side_of_triangle_mesh.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/boost/graph/properties_Surface_mesh_features.h>
#include <CGAL/make_mesh_3.h>
#include <CGAL/refine_mesh_3.h>
#include <boost/iterator/indirect_iterator.hpp>

#include <algorithm>
#include <array>
#include <atomic>
#include <cmath>
#include <cstdint>
#include <memory>
#include <string>
#include <unordered_map>
#include <utility>
#include <vector>

namespace morphomap::detail {

namespace {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_3;
using Domain = CGAL::Polyhedral_complex_mesh_domain_3<Kernel, SurfaceMesh>;
// Mesh_3's types, sequential (repeatable) or parallel (TBB: faster, but the insertion order
// follows the threads, so the mesh differs from run to run).
template <class Concurrency>
struct Mesh3 {
  using Triangulation = typename CGAL::Mesh_triangulation_3<Domain, CGAL::Default, Concurrency>::type;
  using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Triangulation, Domain::Corner_index, Domain::Curve_index>;
  using Criteria = CGAL::Mesh_criteria_3<Triangulation>;
};
using C3t3 = Mesh3<CGAL::Sequential_tag>::C3t3;
using Criteria = Mesh3<CGAL::Sequential_tag>::Criteria;

std::vector<std::array<double, 3>> points_of(const SurfaceMesh& surface) {
  std::vector<std::array<double, 3>> points;
  points.reserve(surface.number_of_vertices());
  for (const auto v : surface.vertices()) {
    const Point& p = surface.point(v);
    points.push_back({p.x(), p.y(), p.z()});
  }
  return points;
}

// The distance to the nearest of some points (a surface's vertices), interpolated trilinearly
// between the corners of a grid, each corner searched once, on first use. Mesh_3 asks for the size
// millions of times (2.3 million searches at 100k faces were 27% of the meshing's CPU time,
// bench/README.md, "Sizing grid"); the grid needs one search per corner near the region. Each corner's value
// depends on its position alone (whichever thread fills it first), so the mesh stays repeatable.
// The distance is 1-Lipschitz: interpolated, it errs by less than the spacing times sqrt(3), and
// the size by the grading times that (a third of the finest size at the spacing Sizing uses).
// Outside the grid: the exact search. The grid reaches up to the surfaces: an exact zone there
// would cost about a tenth more meshing time at 100k faces, and the fold that one real frame's
// field kept without it is removed by the fold repair (bench/README.md, "Sizing grid").
class GridDistance {
 public:
  GridDistance(std::vector<std::array<double, 3>> points, const CGAL::Bbox_3& box, double spacing)
      : exact_(std::move(points)), spacing_(spacing) {
    const double lower[3] = {box.xmin(), box.ymin(), box.zmin()}, upper[3] = {box.xmax(), box.ymax(), box.zmax()};
    double extent = 0.0;
    for (int a = 0; a < 3; ++a) extent = std::max(extent, upper[a] - lower[a]);
    // A grid that fine (a thin shell: small sizes in a large box) would take too much memory:
    // exact searches instead.
    exact_only_ = !(spacing > 0.0) || extent / spacing > kMaxCornersPerAxis;
    if (exact_only_) return;
    std::size_t corners = 1;
    for (int a = 0; a < 3; ++a) {
      origin_[a] = lower[a] - spacing_;
      count_[a] = static_cast<std::int64_t>(std::ceil((upper[a] - lower[a]) / spacing_)) + 3;
      corners *= static_cast<std::size_t>(count_[a]);
    }
    corners_ = std::make_unique<std::atomic<double>[]>(corners);
    for (std::size_t k = 0; k < corners; ++k) corners_[k].store(kUnknown, std::memory_order_relaxed);
  }

  double distance(const Point& p) const {
    if (exact_only_) return exact_.distance(p.x(), p.y(), p.z());
    const double at[3] = {p.x(), p.y(), p.z()};
    std::int64_t cell[3];
    double t[3];
    for (int a = 0; a < 3; ++a) {
      const double f = (at[a] - origin_[a]) / spacing_;
      if (!(f >= 0.0 && f < static_cast<double>(count_[a] - 1))) return exact_.distance(p.x(), p.y(), p.z());
      cell[a] = static_cast<std::int64_t>(f);
      t[a] = f - static_cast<double>(cell[a]);
    }
    double value = 0.0;
    for (int corner = 0; corner < 8; ++corner) {
      double weight = 1.0;
      std::int64_t index[3];
      for (int a = 0; a < 3; ++a) {
        const int up = (corner >> a) & 1;
        index[a] = cell[a] + up;
        weight *= up ? t[a] : 1.0 - t[a];
      }
      value += weight * corner_distance(index);
    }
    return value;
  }

 private:
  static constexpr double kMaxCornersPerAxis = 160.0;  // 4 million corners, 33 MB
  static constexpr double kUnknown = -1.0;

  double corner_distance(const std::int64_t index[3]) const {
    const std::size_t k = static_cast<std::size_t>((index[2] * count_[1] + index[1]) * count_[0] + index[0]);
    double value = corners_[k].load(std::memory_order_relaxed);
    if (value == kUnknown) {
      value = exact_.distance(origin_[0] + static_cast<double>(index[0]) * spacing_,
                              origin_[1] + static_cast<double>(index[1]) * spacing_,
                              origin_[2] + static_cast<double>(index[2]) * spacing_);
      corners_[k].store(value, std::memory_order_relaxed);
    }
    return value;
  }

  NearestPoint exact_;
  bool exact_only_ = false;
  double spacing_ = 0.0;
  double origin_[3] = {0.0, 0.0, 0.0};
  std::int64_t count_[3] = {0, 0, 0};
  std::unique_ptr<std::atomic<double>[]> corners_;
};

// Target edge length at a point: graded from the size at each surface with the distance to it,
// the distance estimated by the nearest surface vertex (interpolated on a grid of twice that
// size: GridDistance); coarser away from the focus points, if any. Mesh_3 copies its sizing
// fields: the grids are shared (also by the parallel mesher's threads).
class Sizing {
 public:
  Sizing(const SurfaceMesh& source, const SurfaceMesh& target, const ShellMeshCriteria& criteria)
      : criteria_(criteria) {
    const CGAL::Bbox_3 box = CGAL::Polygon_mesh_processing::bbox(source) + CGAL::Polygon_mesh_processing::bbox(target);
    source_ = std::make_shared<const GridDistance>(points_of(source), box, kGridFraction * criteria.source_size);
    target_ = std::make_shared<const GridDistance>(points_of(target), box, kGridFraction * criteria.target_size);
    if (criteria.focus.rows() > 0) {
      const double finest = std::min(criteria.source_size, criteria.target_size);
      focus_ = std::make_shared<const GridDistance>(NearestPoint::rows(criteria.focus), box, kGridFraction * finest);
    }
  }

  template <typename Index_>
  double operator()(const Point& p, int, const Index_&) const {
    const double size = near_surfaces(p);
    return size * coarsening(p, size);
  }

  // How many times coarser than near the surfaces the mesh may be at p (1 without focus points).
  double coarsening(const Point& p) const { return focus_ ? coarsening(p, near_surfaces(p)) : 1.0; }

 private:
  double near_surfaces(const Point& p) const {
    const double ds = source_->distance(p);
    const double size = std::min(criteria_.cell_size, criteria_.source_size + criteria_.grading * ds);
    // Skip the second search where it cannot give less.
    if (size <= criteria_.target_size) return size;
    const double dt = target_->distance(p);
    return std::min(size, criteria_.target_size + criteria_.grading * dt);
  }

  double coarsening(const Point& p, double size) const {
    if (!focus_) return 1.0;
    const double beyond = focus_->distance(p) - criteria_.focus_radius;
    if (!(beyond > 0.0)) return 1.0;
    return std::min(criteria_.coarsening, 1.0 + criteria_.focus_grading * beyond / size);
  }

  // The grids' spacing, in sizes at their surface (bench/README.md, "Sizing grid": at 3 and 4 the
  // concentric spheres' RMS grew by 4-7%; at 1 the corners cost as much as the searches saved).
  static constexpr double kGridFraction = 2.0;
  std::shared_ptr<const GridDistance> source_, target_, focus_;
  ShellMeshCriteria criteria_;
};

// The largest distance between a boundary facet and the surface: the criteria's, as coarse as the
// sizes away from the focus points.
class FacetDistance {
 public:
  FacetDistance(const Sizing& sizing, double distance) : sizing_(sizing), distance_(distance) {}

  template <typename Index_>
  double operator()(const Point& p, int, const Index_&) const {
    return distance_ * sizing_.coarsening(p);
  }

 private:
  Sizing sizing_;
  double distance_;
};

// A few vertices of a surface (every n/20-th) inserted as points of its patch.
template <class Complex>
void seed_patch(Complex& c3t3, const Domain& domain, const SurfaceMesh& surface, int patch) {
  using Triangulation = typename Complex::Triangulation;
  Triangulation& tr = c3t3.triangulation();
  const auto weighted = tr.geom_traits().construct_weighted_point_3_object();
  const std::size_t n = surface.number_of_vertices(), stride = std::max<std::size_t>(1, n / 20);
  std::size_t k = 0;
  for (const auto v : surface.vertices()) {
    if (k++ % stride != 0) continue;
    const auto handle = tr.insert(weighted(surface.point(v)));
    if (handle == typename Triangulation::Vertex_handle()) continue;
    c3t3.set_dimension(handle, 2);
    c3t3.set_index(handle, domain.index_from_surface_patch_index(patch));
  }
}

// Delaunay refinement of the complex to the criteria (no perturbation), then optionally exudation
// of slivers until no dihedral angle is below 20 degrees, without a time limit. By default Mesh_3
// stops exudation after as many seconds as the refinement took, so how many slivers it removed
// depended on the machine's load, and the same input gave other meshes and ends from call to
// call. Without a bound it removes every sliver it can, at twice the CPU time of the whole
// meshing for no better ends. Since exits are interpolated from the mesh's corners (laplace3d.cpp),
// 20 degrees gives ends as good as 30 did before, in about a third of the exudation time
// (bench/README.md, "Sliver bound").
constexpr double kSliverBound = 20.0;

template <class Complex, class MeshCriteria>
void refine(Complex& c3t3, const Domain& domain, const MeshCriteria& criteria, bool exude) {
  namespace params = CGAL::parameters;
  if (exude) {
    CGAL::refine_mesh_3(c3t3, domain, criteria, params::no_perturb(),
                        params::exude(params::time_limit = 0, params::sliver_bound = kSliverBound));
  } else {
    CGAL::refine_mesh_3(c3t3, domain, criteria, params::no_perturb(), params::no_exude());
  }
}

// The tetrahedra of the complex, with their neighbours and the kind of each boundary face:
// patch_kind(patch index) -> FacePatch.
template <class Complex, class PatchKind>
ShellMesh to_shell_mesh(const Complex& c3t3, PatchKind patch_kind) {
  using Triangulation = typename Complex::Triangulation;
  ShellMesh mesh;
  const Triangulation& tr = c3t3.triangulation();
  std::unordered_map<typename Triangulation::Cell_handle, Index> cell_index;
  std::unordered_map<typename Triangulation::Vertex_handle, Index> vertex_index;
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
        mesh.patches(t, i) = patch_kind(patch);
      }
    }
  }
  return mesh;
}

}  // namespace

namespace {
constexpr const char* kSelfIntersecting =
    "intersects itself; the mapping needs a simple closed surface (a mask contoured without "
    "smoothing can touch itself at a voxel edge: smooth or remesh it)";
}  // namespace

struct ClosedSurface::Mesh {
  SurfaceMesh surface;
};

ClosedSurface::ClosedSurface(const Points3Ref& vertices, const FacesRef& faces)
    : mesh_(std::make_unique<Mesh>(Mesh{to_surface_mesh(vertices, faces)})) {}
ClosedSurface::~ClosedSurface() = default;

Nesting classify_nesting(const ClosedSurface& source_surface, const ClosedSurface& target_surface) {
  try {
    const SurfaceMesh& source = source_surface.mesh().surface;
    const SurfaceMesh& target = target_surface.mesh().surface;
    // Mesh_3 on a self-intersecting surface may crash rather than fail. (The two tests at once:
    // at 100k faces they were a twentieth of a whole diffusion mapping.)
    bool source_meets_itself = false, target_meets_itself = false;
    run_both(
        [&] {
          source_meets_itself =
              !source_surface.known_simple() && CGAL::Polygon_mesh_processing::does_self_intersect(source);
        },
        [&] {
          target_meets_itself =
              !target_surface.known_simple() && CGAL::Polygon_mesh_processing::does_self_intersect(target);
        });
    if (source_meets_itself) throw InvalidInput(std::string("s1: ") + kSelfIntersecting);
    source_surface.mark_simple();
    if (target_meets_itself) throw InvalidInput(std::string("s2: ") + kSelfIntersecting);
    target_surface.mark_simple();
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

std::vector<char> inside_surface(const ClosedSurface& surface, const Points3Ref& queries) {
  std::vector<char> inside(static_cast<std::size_t>(queries.rows()), 0);
  try {
    const CGAL::Side_of_triangle_mesh<SurfaceMesh, Kernel> side(surface.mesh().surface);
    for (Index i = 0; i < queries.rows(); ++i) {
      inside[static_cast<std::size_t>(i)] =
          side(Point(queries(i, 0), queries(i, 1), queries(i, 2))) != CGAL::ON_UNBOUNDED_SIDE;
    }
  } catch (const CGAL::Failure_exception& e) {
    throw GeometryError(std::string("locating points against a surface failed: ") + e.what());
  }
  return inside;
}

namespace {

template <class Concurrency>
ShellMesh mesh_nested(const ClosedSurface& source, const ClosedSurface& target, bool source_inside,
                      const ShellMeshCriteria& criteria) {
  typename Mesh3<Concurrency>::C3t3 c3t3;
  try {
    const SurfaceMesh* patches[2] = {&source.mesh().surface, &target.mesh().surface};
    // (subdomain inside, subdomain outside) of each outward-oriented patch; the shell is 1.
    const std::pair<int, int> inner(0, 1), outer(1, 0);
    const std::pair<int, int> sides[2] = {source_inside ? inner : outer, source_inside ? outer : inner};
    const Sizing sizing(*patches[0], *patches[1], criteria);
    CGAL::Random random(criteria.seed);
    // (The domain keeps copies of the patches.)
    const Domain domain(boost::make_indirect_iterator(patches), boost::make_indirect_iterator(patches + 2), sides,
                        sides + 2, &random);
    namespace params = CGAL::parameters;
    const typename Mesh3<Concurrency>::Criteria mesh_criteria(
        params::facet_angle = 25.0, params::facet_size = sizing,
        params::facet_distance = FacetDistance(sizing, criteria.facet_distance), params::cell_radius_edge_ratio = 3.0,
        params::cell_size = sizing);
    // Mesh_3's own initial points come from rays shot from the centre of the bounding box and may
    // all land on the outer surface, so that the inner one is never found: start instead from a
    // few vertices of each surface, as points of its patch.
    // (Asking for the construction object makes the domain detect its borders, as make_mesh_3 would.)
    (void)domain.construct_initial_points_object();
    for (int patch = 1; patch <= 2; ++patch) seed_patch(c3t3, domain, *patches[patch - 1], patch);
    refine(c3t3, domain, mesh_criteria, criteria.exude);
  } catch (const CGAL::Failure_exception& e) {
    throw GeometryError(std::string("meshing the region between the surfaces failed: ") + e.what());
  }

  return to_shell_mesh(c3t3, [](int patch) {
    return patch == 1 ? source_face : patch == 2 ? target_face : other_face;
  });
}

}  // namespace

ShellMesh mesh_shell(const ClosedSurface& source, const ClosedSurface& target, bool source_inside,
                     const ShellMeshCriteria& criteria) {
  return criteria.parallel ? mesh_nested<CGAL::Parallel_tag>(source, target, source_inside, criteria)
                           : mesh_nested<CGAL::Sequential_tag>(source, target, source_inside, criteria);
}

// Each patch: a connected piece of one surface between the curves where the surfaces cross,
// oriented outwards of its surface.
struct CrossingRegion::Patches {
  SurfaceMesh source, target;       // the whole surfaces (for the sizing field)
  std::vector<SurfaceMesh> meshes;  // the patches
  std::vector<char> from_source;    // the patch is part of S1 (else of S2)
  std::vector<char> inside_other;   // it lies inside the other surface
  std::vector<char> coincident;     // it lies on the other surface, both facing the same way
  std::vector<char> has_border;     // it ends at a crossing curve (a patch without one is a
                                    // whole component of a surface that the other does not cut)
  double volume = 0.0;
};

namespace {

// The faces of each connected component of mesh, bounded by the constrained edges, as meshes.
template <class ConstrainedMap>
std::vector<SurfaceMesh> split_along(SurfaceMesh& mesh, const ConstrainedMap& constrained,
                                     std::vector<char>& has_border) {
  namespace PMP = CGAL::Polygon_mesh_processing;
  auto component = mesh.add_property_map<SurfaceMesh::Face_index, std::size_t>("f:component", 0).first;
  const std::size_t count =
      PMP::connected_components(mesh, component, CGAL::parameters::edge_is_constrained_map(constrained));
  std::vector<SurfaceMesh> parts(count);
  std::vector<std::unordered_map<std::size_t, SurfaceMesh::Vertex_index>> handle(count);
  std::vector<char> border(count, 0);
  for (const auto f : mesh.faces()) {
    const std::size_t k = component[f];
    std::array<SurfaceMesh::Vertex_index, 3> corner;
    int i = 0;
    for (const auto h : CGAL::halfedges_around_face(mesh.halfedge(f), mesh)) {
      const auto v = mesh.target(h);
      const auto [it, added] = handle[k].emplace(std::size_t(v), SurfaceMesh::Vertex_index());
      if (added) it->second = parts[k].add_vertex(mesh.point(v));
      corner[i++] = it->second;
      if (constrained[mesh.edge(h)]) border[k] = 1;
    }
    parts[k].add_face(corner[0], corner[1], corner[2]);
  }
  has_border.insert(has_border.end(), border.begin(), border.end());
  return parts;
}

// Signed volume enclosed with the origin o (positive for faces seen anticlockwise from outside).
double signed_volume(const SurfaceMesh& mesh, const Point& o) {
  double volume = 0.0;
  for (const auto f : mesh.faces()) {
    std::array<Kernel::Vector_3, 3> p;
    int i = 0;
    for (const auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) p[i++] = mesh.point(v) - o;
    volume += CGAL::scalar_product(p[0], CGAL::cross_product(p[1], p[2])) / 6.0;
  }
  return volume;
}

}  // namespace

CrossingRegion::CrossingRegion(const ClosedSurface& source_surface, const ClosedSurface& target_surface)
    : patches_(std::make_unique<Patches>()) {
  namespace PMP = CGAL::Polygon_mesh_processing;
  Patches& p = *patches_;
  try {
    p.source = source_surface.mesh().surface;
    p.target = target_surface.mesh().surface;
    SurfaceMesh source = p.source, target = p.target;
    auto source_cut = source.add_property_map<SurfaceMesh::Edge_index, bool>("e:cut", false).first;
    auto target_cut = target.add_property_map<SurfaceMesh::Edge_index, bool>("e:cut", false).first;
    PMP::corefine(source, target, CGAL::parameters::edge_is_constrained_map(source_cut),
                  CGAL::parameters::edge_is_constrained_map(target_cut));
    p.meshes = split_along(source, source_cut, p.has_border);
    p.from_source.assign(p.meshes.size(), 1);
    for (auto& part : split_along(target, target_cut, p.has_border)) p.meshes.push_back(std::move(part));
    p.from_source.resize(p.meshes.size(), 0);

    // Inside or outside the other surface: the side of the centroid of the patch's largest face.
    const CGAL::Side_of_triangle_mesh<SurfaceMesh, Kernel> in_source(p.source), in_target(p.target);
    for (std::size_t k = 0; k < p.meshes.size(); ++k) {
      const SurfaceMesh& mesh = p.meshes[k];
      Point centroid;
      std::array<Point, 3> largest_face;
      double largest = -1.0;
      for (const auto f : mesh.faces()) {
        std::array<Point, 3> q;
        int i = 0;
        for (const auto v : CGAL::vertices_around_face(mesh.halfedge(f), mesh)) q[i++] = mesh.point(v);
        const double area = CGAL::squared_area(q[0], q[1], q[2]);
        if (area > largest) largest = area, centroid = CGAL::centroid(q[0], q[1], q[2]), largest_face = q;
      }
      const auto& other_side = p.from_source[k] ? in_target : in_source;
      const CGAL::Bounded_side side = other_side(centroid);
      p.inside_other.push_back(side == CGAL::ON_BOUNDED_SIDE ? 1 : 0);
      p.coincident.push_back(side == CGAL::ON_BOUNDARY ? 1 : 0);
      if (side != CGAL::ON_BOUNDARY) continue;
      // Which way the other surface faces there: a step off the face along its outward normal,
      // a thousandth of the face's size, lands outside the other surface where both face the
      // same way (frames contoured on one grid where the tissue did not move: the patch bounds
      // no piece, as the paper's curves meet at a shared stretch), inside where they face each
      // other (bodies pressed together, whose pieces would share the patch as S1 and as S2).
      const Kernel::Vector_3 normal = CGAL::unit_normal(largest_face[0], largest_face[1], largest_face[2]);
      if (other_side(centroid + 1e-3 * std::sqrt(largest) * normal) == CGAL::ON_BOUNDED_SIDE) {
        throw InvalidInput(
            "s2: presses against s1 from outside over a patch; the region between them is not a "
            "volume there");
      }
    }
  } catch (const CGAL::Failure_exception& e) {
    throw GeometryError(std::string("cutting the surfaces where they cross failed: ") + e.what());
  }

  // S1 \ S2 is bounded by the parts of S1 outside S2 (outwards) and of S2 inside S1 (inwards),
  // S2 \ S1 likewise: the pieces' volume is the sum over the outside patches minus the inside ones.
  // A coincident patch bounds neither piece (both are empty on either side of it).
  const Point origin = CGAL::centroid(p.source.points().begin(), p.source.points().end());
  for (std::size_t k = 0; k < p.meshes.size(); ++k) {
    if (p.coincident[k]) continue;
    const double volume = signed_volume(p.meshes[k], origin);
    p.volume += p.inside_other[k] ? -volume : volume;
  }
}

CrossingRegion::~CrossingRegion() = default;

double CrossingRegion::volume() const { return patches_->volume; }

ShellMesh CrossingRegion::mesh(const ShellMeshCriteria& criteria) const {
  const Patches& p = *patches_;
  C3t3 c3t3;
  std::vector<int> patch_of;  // the Domain's patch index (from 1) -> index in p.meshes
  try {
    // (subdomain inside, subdomain outside) of each patch: S1 \ S2 is 1, S2 \ S1 is 2, the
    // intersection and the outside of both are 0 (not meshed). Coincident patches bound neither.
    std::vector<std::pair<int, int>> sides;
    std::vector<const SurfaceMesh*> kept;
    for (std::size_t k = 0; k < p.meshes.size(); ++k) {
      if (p.coincident[k]) continue;
      const int piece_inside = p.from_source[k] ? 1 : 2, piece_outside = p.from_source[k] ? 2 : 1;
      sides.push_back(p.inside_other[k] ? std::make_pair(0, piece_outside) : std::make_pair(piece_inside, 0));
      kept.push_back(&p.meshes[k]);
      patch_of.push_back(static_cast<int>(k));
    }
    const Sizing sizing(p.source, p.target, criteria);
    CGAL::Random random(criteria.seed);
    const Domain domain(boost::make_indirect_iterator(kept.begin()), boost::make_indirect_iterator(kept.end()),
                        sides.begin(), sides.end(), &random);
    namespace params = CGAL::parameters;
    // First the crossing curves, protected by balls of the local size, and a coarse mesh; then
    // the few vertices of any patch no curve bounds (Mesh_3 may not find it by itself); then the
    // refinement to the real criteria.
    const Criteria coarse(params::edge_size = sizing, params::facet_angle = 25.0,
                          params::facet_size = criteria.cell_size, params::cell_radius_edge_ratio = 3.0,
                          params::cell_size = criteria.cell_size);
    c3t3 = CGAL::make_mesh_3<C3t3>(domain, coarse, params::features(domain), params::no_perturb(), params::no_exude());
    for (std::size_t i = 0; i < kept.size(); ++i) {
      if (!p.has_border[patch_of[i]]) seed_patch(c3t3, domain, *kept[i], static_cast<int>(i) + 1);
    }
    const Criteria fine(params::edge_size = sizing, params::facet_angle = 25.0, params::facet_size = sizing,
                        params::facet_distance = criteria.facet_distance, params::cell_radius_edge_ratio = 3.0,
                        params::cell_size = sizing);
    refine(c3t3, domain, fine, criteria.exude);
  } catch (const CGAL::Failure_exception& e) {
    throw GeometryError(std::string("meshing the region between the surfaces failed: ") + e.what());
  }
  const int count = static_cast<int>(patch_of.size());
  return to_shell_mesh(c3t3, [&](int patch) {
    if (patch < 1 || patch > count) return other_face;
    return p.from_source[patch_of[patch - 1]] ? source_face : target_face;
  });
}

}  // namespace morphomap::detail
