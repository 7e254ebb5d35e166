// The only translation unit with CGAL's 2D mesher: it compiles slowly.
#include "diffusion/region_mesh.hpp"

#include "common/interrupt_check.hpp"
#include "common/segment_pairs.hpp"
#include "curves/unchecked.hpp"

#include <morphomap/curve_queries.hpp>
#include <morphomap/errors.hpp>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Delaunay_mesh_face_base_2.h>
#include <CGAL/Delaunay_mesh_size_criteria_2.h>
#include <CGAL/Delaunay_mesher_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Spatial_sort_traits_adapter_2.h>
#include <CGAL/Triangulation_vertex_base_with_info_2.h>
#include <CGAL/property_map.h>
#include <CGAL/spatial_sort.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <queue>
#include <sstream>
#include <string>
#include <unordered_map>

namespace morphomap::detail {

namespace {

struct VertexInfo {
  Index input = -1;
  Index index = -1;
  // 0: put in by the mesher, 1: seeded on the lattice, 2: any other (the loops' points, the points
  // splitting their edges, the graded layers)
  std::uint8_t kind = 0;
};

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using VertexBase = CGAL::Triangulation_vertex_base_with_info_2<VertexInfo, Kernel>;
using FaceBase = CGAL::Delaunay_mesh_face_base_2<Kernel>;
using Tds = CGAL::Triangulation_data_structure_2<VertexBase, FaceBase>;
// Exact_predicates_tag: constraints may cross (crossing curves); CGAL adds the crossing points.
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<Kernel, Tds, CGAL::Exact_predicates_tag>;
using Point = Cdt::Point;

// CGAL's criteria (smallest angle, longest edge), except that a triangle with two lattice vertices
// and a third one from the lattice or the mesher may be as long as a lattice triangle's
// circumdiameter (2 / sqrt(3) spacings, 1.12 max_edge). A point the mesher puts inside the lattice
// joins the lattice points whose circumcircles hold it, all within that distance. Under the plain
// bound (a spacing is 0.97 of it) its spokes to the next row were too long: the mesher split them
// at their triangles' circumcentres, which are the centres of the next lattice triangles, and so
// on along a lattice direction, refining deep into the lattice and bending the streamlines there
// (bench/README.md, "Diffusion mapping", has the counts).
// Triangles with a loop's or a layer's point keep the plain bound (the strip is graded as before).
class Criteria : public CGAL::Delaunay_mesh_size_criteria_2<Cdt> {
  using Base = CGAL::Delaunay_mesh_size_criteria_2<Cdt>;

 public:
  Criteria(double aspect_bound, double size_bound, double lattice_bound)
      : CGAL::Delaunay_mesh_criteria_2<Cdt>(aspect_bound),
        Base(aspect_bound, size_bound),
        lattice_bound_(lattice_bound) {}

  class Is_bad : public Base::Is_bad {
   public:
    Is_bad(double aspect_bound, double size_bound, double lattice_bound, const Geom_traits& traits)
        : Base::Is_bad(aspect_bound, size_bound, traits), lattice_squared_(lattice_bound * lattice_bound) {}
    using Base::Is_bad::operator();
    CGAL::Mesh_2::Face_badness operator()(const Cdt::Face_handle& f, Quality& q) const {
      const Point &a = f->vertex(0)->point(), &b = f->vertex(1)->point(), &c = f->vertex(2)->point();
      double sides[3] = {CGAL::squared_distance(b, c), CGAL::squared_distance(c, a), CGAL::squared_distance(a, b)};
      std::sort(sides, sides + 3);
      int kinds[3] = {0, 0, 0};
      for (int i = 0; i < 3; ++i) ++kinds[f->vertex(i)->info().kind];
      const bool in_lattice = kinds[1] >= 2 && kinds[2] == 0;
      const double bound = in_lattice ? std::max(lattice_squared_, this->squared_size_bound) : this->squared_size_bound;
      q.second = bound > 0 ? sides[2] / bound : 0.0;
      if (q.size() > 1) {
        q.first = 1;
        return CGAL::Mesh_2::IMPERATIVELY_BAD;
      }
      const double area = 2 * CGAL::area(a, b, c);
      q.first = area * area / (sides[2] * sides[1]);  // squared sine of the smallest angle
      return q.sine() < this->B ? CGAL::Mesh_2::BAD : CGAL::Mesh_2::NOT_BAD;
    }

   private:
    double lattice_squared_;
  };

  Is_bad is_bad_object() const { return Is_bad(this->bound(), size_bound(), lattice_bound_, this->traits); }

 private:
  double lattice_bound_;
};

constexpr std::size_t kMaxVertices = 8'000'000;
// Lattice points keep a whole spacing from the loops: the mesher then grades the strip between
// the loops' points and the lattice with well-shaped triangles (at half a spacing the worst
// streamlines in the closed-form tests were 2-3 times further off).
constexpr double kClearance = 1.0;
// The lattice spacing over the mesh size: a little under, so that rounding does not make the
// mesher split lattice edges.
constexpr double kLattice = 0.97;

[[noreturn]] void too_many_vertices() {
  throw GeometryError("meshing the region between the curves needs more than " + std::to_string(kMaxVertices) +
                      " vertices: the region is degenerate, or the mesh size far too small for it");
}

// Faces inside an odd number of loops: flood fill from the infinite faces, one connected
// component at a time, a constrained edge raising the nesting level by one.
void mark_odd_nesting(Cdt& cdt) {
  std::unordered_map<Cdt::Face_handle, int> level;
  std::queue<std::pair<Cdt::Face_handle, int>> border;
  border.push({cdt.infinite_face(), 0});
  while (!border.empty()) {
    const auto [start, depth] = border.front();
    border.pop();
    if (level.count(start)) continue;
    std::queue<Cdt::Face_handle> component;
    component.push(start);
    level[start] = depth;
    while (!component.empty()) {
      if (level.size() % 65536 == 0) check_interrupt();
      const Cdt::Face_handle f = component.front();
      component.pop();
      for (int i = 0; i < 3; ++i) {
        const Cdt::Face_handle g = f->neighbor(i);
        if (level.count(g)) continue;
        if (cdt.is_constrained(Cdt::Edge(f, i))) {
          border.push({g, depth + 1});
        } else {
          level[g] = depth;
          component.push(g);
        }
      }
    }
  }
  for (auto f = cdt.all_faces_begin(); f != cdt.all_faces_end(); ++f) {
    f->set_in_domain(!cdt.is_infinite(f) && level[f] % 2 == 1);
  }
}

// The points (x, y pairs) that lie at least away[k] from every loop.
std::vector<Point> clear_of_loops(const std::vector<CurveIndex>& loops, const std::vector<double>& xy,
                                  const std::vector<double>& away) {
  const Index count = static_cast<Index>(away.size());
  const Eigen::Map<const Points2> points(xy.data(), count, 2);
  std::vector<double> distance(away.size(), std::numeric_limits<double>::infinity());
  for (const CurveIndex& loop : loops) {
    const CurveHits hits = CurveIndexUnchecked::closest_points(loop, points);  // lattice points: finite
    for (Index k = 0; k < count; ++k) distance[k] = std::min(distance[k], hits.distances[k]);
  }
  std::vector<Point> kept;
  for (Index k = 0; k < count; ++k) {
    if (distance[k] >= away[k]) kept.emplace_back(points(k, 0), points(k, 1));
  }
  return kept;
}

// Interior vertices from a triangular lattice of spacing `edge` (equilateral triangles, the best
// shape for P1): its points inside an odd number of loops (scan line by scan line, as the region
// is defined) and at least `clearance` times the spacing from the loops. Seeding them at once and
// leaving the mesher only the strip along the loops is several times faster than growing the whole
// mesh by refinement, one circumcentre at a time.
std::vector<Point> lattice_points(const std::vector<Points2>& loops, const std::vector<CurveIndex>& indexes,
                                  double edge, double clearance) {
  const double row = edge * std::sqrt(3.0) / 2.0;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const Points2& loop : loops)
    lo = std::min(lo, loop.col(1).minCoeff()), hi = std::max(hi, loop.col(1).maxCoeff());
  const double first_row = std::ceil(lo / row), rows = std::floor(hi / row) - first_row + 1.0;
  if (!(rows <= static_cast<double>(kMaxVertices))) too_many_vertices();
  // Where each row crosses the loops; an edge holds the rows in [its lower y, its upper y).
  std::vector<std::vector<double>> crossings(static_cast<std::size_t>(std::max(rows, 0.0)));
  for (const Points2& loop : loops) {
    for (Index k = 0; k < loop.rows(); ++k) {
      const Index next = (k + 1) % loop.rows();
      const double ax = loop(k, 0), ay = loop(k, 1), bx = loop(next, 0), by = loop(next, 1);
      if (ay == by) continue;
      const double y0 = std::min(ay, by), y1 = std::max(ay, by);
      for (auto j = static_cast<std::int64_t>(std::ceil(y0 / row)); j * row < y1; ++j) {
        const double y = j * row;
        if (y < y0) continue;
        crossings[static_cast<std::size_t>(j - first_row)].push_back(ax + (y - ay) * (bx - ax) / (by - ay));
      }
    }
  }
  double count = 0.0;
  for (auto& xs : crossings) {
    std::sort(xs.begin(), xs.end());
    for (std::size_t k = 0; k + 1 < xs.size(); k += 2) count += (xs[k + 1] - xs[k]) / edge + 1.0;
  }
  if (count > static_cast<double>(kMaxVertices)) too_many_vertices();
  std::vector<double> candidates;  // x, y pairs
  for (std::size_t r = 0; r < crossings.size(); ++r) {
    const auto j = static_cast<std::int64_t>(first_row) + static_cast<std::int64_t>(r);
    const double shift = (j % 2 != 0) ? 0.5 * edge : 0.0;
    const std::vector<double>& xs = crossings[r];
    for (std::size_t k = 0; k + 1 < xs.size(); k += 2) {
      for (auto i = static_cast<std::int64_t>(std::ceil((xs[k] - shift) / edge)); i * edge + shift <= xs[k + 1]; ++i) {
        candidates.push_back(i * edge + shift), candidates.push_back(j * row);
      }
    }
  }
  const std::vector<double> away(candidates.size() / 2, clearance * edge);
  return clear_of_loops(indexes, candidates, away);
}

// Graded layers between the loops' points and the lattice: layer k keeps every 2^k-th point of a
// loop and lies sqrt(3)/2 * 2^k local spacings from it along its normal, on the region's side (the
// marked faces tell), so that the mesher is left little to grade. Points closer to a loop than
// most of their layer's distance (narrow gaps, sharp bends) are dropped. Without them the mesher
// grades a strip a lattice spacing wide down to the points' spacing on its own, inserting into
// fans of long thin triangles, and its time grows faster than the number of points.
std::vector<Point> layer_points(const Cdt& cdt, const std::vector<Points2>& loops,
                                const std::vector<CurveIndex>& indexes, double limit) {
  std::vector<double> xy, away;
  Cdt::Face_handle hint;
  for (const Points2& loop : loops) {
    const Index n = loop.rows();
    for (Index i = 0; i < n; ++i) {
      if (i % 4096 == 0) check_interrupt();
      const Eigen::RowVector2d before = loop.row((i + n - 1) % n), here = loop.row(i), after = loop.row((i + 1) % n);
      const Eigen::RowVector2d chord = after - before;
      const double spacing = 0.5 * ((here - before).norm() + (after - here).norm()), length = chord.norm();
      // Where the points are less than a few layers finer than the lattice, the mesher grades
      // well on its own (and the closed-form tests come out more accurate without the layers).
      if (!(length > 0.0) || spacing > 0.25 * limit) continue;
      const Eigen::RowVector2d normal(-chord.y() / length, chord.x() / length);
      for (Index stride = 1; i % stride == 0 && stride <= n; stride *= 2) {
        const double d = std::sqrt(3.0) / 2.0 * spacing * static_cast<double>(stride);
        if (d >= limit) break;
        for (const double side : {1.0, -1.0}) {
          const Eigen::RowVector2d q = here + side * d * normal;
          const Point p(q.x(), q.y());
          const Cdt::Face_handle f = cdt.locate(p, hint);
          hint = f;
          if (cdt.is_infinite(f) || !f->is_in_domain()) continue;
          xy.push_back(q.x()), xy.push_back(q.y()), away.push_back(d);
        }
      }
    }
  }
  for (double& d : away) d *= 0.7;
  return clear_of_loops(indexes, xy, away);
}

// Which edges of a loop run along another of its edges (collinear, sharing more than a point; per
// loop, edge i from point i to the next): a piece's loop may, along a stretch where the curves
// touch. Edges of two loops that do are refused. Such edges must not be split beforehand: the split
// points are rounded off the shared line, and CGAL computes the crossings of the nearly collinear
// constraints that leaves inexactly (a segfault and an endless refinement were found). Unsplit,
// each edge's end points lie exactly on the other and the exact predicates join them.
std::vector<std::vector<char>> edges_running_together(const std::vector<Points2>& loops) {
  std::vector<std::vector<char>> flags(loops.size());
  std::vector<std::pair<detail::Point, detail::Point>> edges;
  std::vector<std::pair<std::size_t, Index>> owner;  // (loop, edge) of each
  std::vector<SegmentBox> boxes;
  for (std::size_t l = 0; l < loops.size(); ++l) {
    const Points2& loop = loops[l];
    flags[l].assign(loop.rows(), 0);
    for (Index i = 0; i < loop.rows(); ++i) {
      const detail::Point a = point_at(loop, i), b = point_at(loop, (i + 1) % loop.rows());
      if (a == b) continue;
      boxes.emplace_back(a, b, edges.size());
      edges.emplace_back(a, b);
      owner.emplace_back(l, i);
    }
  }
  const auto run_together = [&](Index i, Index j) {
    const auto& [a, b] = edges[i];
    const auto& [c, d] = edges[j];
    if (orient(a, b, c) != 0 || orient(a, b, d) != 0) return false;
    // Collinear: they share more than a point where their extents along the line overlap.
    const bool along_x = a.x() != b.x();
    const double lo1 = along_x ? std::min(a.x(), b.x()) : std::min(a.y(), b.y());
    const double hi1 = along_x ? std::max(a.x(), b.x()) : std::max(a.y(), b.y());
    const double lo2 = along_x ? std::min(c.x(), d.x()) : std::min(c.y(), d.y());
    const double hi2 = along_x ? std::max(c.x(), d.x()) : std::max(c.y(), d.y());
    return std::min(hi1, hi2) > std::max(lo1, lo2);
  };
  IndexPairs shared;
  test_overlapping_pairs(std::move(boxes), run_together, &shared);
  for (const auto& [i, j] : shared) {
    if (owner[i].first != owner[j].first) {
      // Two closed curves (two loops) that run together: even unsplit, their crossing constraints
      // crashed CGAL, and the odd-nesting rule cannot tell the sides of a stretch bounded twice.
      const auto& [a, b] = edges[i];
      const auto& [c, d] = edges[j];
      const auto from = std::max(std::min(a, b), std::min(c, d)), to = std::min(std::max(a, b), std::max(c, d));
      std::ostringstream where;  // six significant digits, whatever the scale
      where << "the curves run along each other from (" << from.x() << ", " << from.y() << ") to (" << to.x() << ", "
            << to.y()
            << "): the region between them has no width there (map_curves splits such pairs where they touch)";
      throw GeometryError(where.str());
    }
    for (const Index e : {i, j}) flags[owner[e].first][owner[e].second] = 1;
  }
  return flags;
}

}  // namespace

RegionMesh mesh_region(const std::vector<Points2>& loops, double max_edge) {
  const std::vector<std::vector<char>> unsplit = edges_running_together(loops);
  Cdt cdt;
  std::vector<Point> points;
  for (const Points2& loop : loops) {
    for (Index i = 0; i < loop.rows(); ++i) points.emplace_back(loop(i, 0), loop(i, 1));
  }
  // Inserting points in their order along a curve (nearly co-circular) costs many flips per point:
  // insert them in spatial (Hilbert) order, each near the last.
  std::vector<std::size_t> order(points.size());
  for (std::size_t i = 0; i < order.size(); ++i) order[i] = i;
  using SortTraits = CGAL::Spatial_sort_traits_adapter_2<Kernel, CGAL::Pointer_property_map<Point>::type>;
  CGAL::spatial_sort(order.begin(), order.end(), SortTraits(CGAL::make_property_map(points)));
  std::vector<Cdt::Vertex_handle> handles(points.size());
  try {
    Cdt::Face_handle hint;
    for (const std::size_t i : order) {
      if (i % 4096 == 0) check_interrupt();
      const auto v = cdt.insert(points[i], hint);
      if (v->info().input < 0 || static_cast<Index>(i) < v->info().input) v->info().input = static_cast<Index>(i);
      v->info().kind = 2;
      handles[i] = v;
      hint = v->face();
    }
    if (max_edge > 0) {  // the split edges below must not run away either
      double pieces = 0.0;
      for (const Points2& loop : loops) {
        for (Index i = 0; i < loop.rows(); ++i) {
          pieces += std::ceil((loop.row((i + 1) % loop.rows()) - loop.row(i)).norm() / max_edge);
        }
      }
      if (!(pieces <= static_cast<double>(kMaxVertices))) too_many_vertices();
    }
    Index first = 0;
    for (std::size_t l = 0; l < loops.size(); ++l) {
      const Points2& loop = loops[l];
      const Index n = loop.rows();
      for (Index i = 0; i < n; ++i) {
        if (i % 4096 == 0) check_interrupt();
        const auto a = handles[first + i], b = handles[first + (i + 1) % n];
        if (a == b) continue;
        // Edges longer than the mesh size are split evenly beforehand, as the mesher would.
        const double length = std::sqrt(CGAL::squared_distance(a->point(), b->point()));
        const int pieces = max_edge > 0 && !unsplit[l][i] ? static_cast<int>(std::ceil(length / max_edge)) : 1;
        auto previous = a;
        for (int k = 1; k < pieces; ++k) {
          const double t = static_cast<double>(k) / pieces;
          const Point p(a->point().x() + t * (b->point().x() - a->point().x()),
                        a->point().y() + t * (b->point().y() - a->point().y()));
          const auto v = cdt.insert(p, previous->face());
          v->info().kind = 2;
          if (v != previous) cdt.insert_constraint(previous, v);
          previous = v;
        }
        if (previous != b) cdt.insert_constraint(previous, b);
      }
      first += n;
    }
    // Collinear loops (curves that run together all along) bound no area at all.
    if (cdt.dimension() < 2) throw GeometryError("the region between the curves is empty");
    if (max_edge > 0) {
      std::vector<CurveIndex> indexes;
      for (const Points2& loop : loops) indexes.push_back(CurveIndexUnchecked::build(loop, true));
      std::vector<Point> seeds = lattice_points(loops, indexes, kLattice * max_edge, kClearance);
      const std::size_t on_lattice = seeds.size();
      mark_odd_nesting(cdt);  // layer_points keeps the points on the region's side
      const std::vector<Point> layers = layer_points(cdt, loops, indexes, 0.9 * kClearance * max_edge);
      seeds.insert(seeds.end(), layers.begin(), layers.end());
      std::vector<std::size_t> seed_order(seeds.size());
      for (std::size_t i = 0; i < seed_order.size(); ++i) seed_order[i] = i;
      CGAL::spatial_sort(seed_order.begin(), seed_order.end(), SortTraits(CGAL::make_property_map(seeds)));
      Cdt::Face_handle hint;
      for (const std::size_t i : seed_order) {
        if (i % 4096 == 0) check_interrupt();
        const auto v = cdt.insert(seeds[i], hint);
        if (v->info().kind == 0) v->info().kind = i < on_lattice ? 1 : 2;
        hint = v->face();
      }
    }
    mark_odd_nesting(cdt);
    // Refine step by step so that a degenerate input cannot run away with time and memory.
    CGAL::Delaunay_mesher_2<Cdt, Criteria> mesher(
        cdt, Criteria(0.125, max_edge > 0 ? max_edge : 0.0, 2.0 / std::sqrt(3.0) * kLattice * max_edge * 1.001));
    mesher.init(true);
    while (mesher.try_one_step_refine_mesh()) {
      if (cdt.number_of_vertices() > kMaxVertices) too_many_vertices();
      check_interrupt();
    }
  } catch (const CGAL::Failure_exception& e) {
    throw GeometryError(std::string("meshing the region between the curves failed: ") + e.what());
  }

  RegionMesh mesh;
  Index vertex_count = 0, triangle_count = 0;
  std::unordered_map<Cdt::Face_handle, Index> face_index;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (!f->is_in_domain()) continue;
    if (triangle_count % 65536 == 0) check_interrupt();
    face_index[f] = triangle_count++;
    for (int i = 0; i < 3; ++i) {
      if (f->vertex(i)->info().index < 0) f->vertex(i)->info().index = vertex_count++;
    }
  }
  mesh.vertices.resize(vertex_count, 2);
  mesh.input.assign(vertex_count, -1);
  mesh.on_boundary.assign(vertex_count, 0);
  mesh.triangles.resize(triangle_count, 3);
  mesh.neighbours.resize(triangle_count, 3);
  for (const auto& [f, t] : face_index) {
    for (int i = 0; i < 3; ++i) {
      const auto v = f->vertex(i);
      const Index k = v->info().index;
      mesh.triangles(t, i) = k;
      mesh.vertices(k, 0) = v->point().x();
      mesh.vertices(k, 1) = v->point().y();
      mesh.input[k] = v->info().input;
      const auto across = face_index.find(f->neighbor(i));
      mesh.neighbours(t, i) = across == face_index.end() ? -1 : across->second;
      if (cdt.is_constrained(Cdt::Edge(f, i))) {
        mesh.on_boundary[f->vertex(Cdt::cw(i))->info().index] = 1;
        mesh.on_boundary[f->vertex(Cdt::ccw(i))->info().index] = 1;
      }
    }
  }
  mesh.of_input.resize(handles.size());
  for (std::size_t i = 0; i < handles.size(); ++i) mesh.of_input[i] = handles[i]->info().index;
  return mesh;
}

}  // namespace morphomap::detail
