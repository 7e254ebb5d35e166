// P1 finite elements for the Laplace equation on the region mesh, and streamline tracing.
#include <morphomap/curve_geometry.hpp>
#include <morphomap/curve_queries.hpp>
#include <morphomap/errors.hpp>
#include <morphomap/laplace.hpp>
#include <morphomap/transform.hpp>

#include "common/interrupt_check.hpp"
#include "common/mesh_adjacency.hpp"
#include "common/numbers.hpp"
#include "common/validation.hpp"
#include "curves/inside.hpp"
#include "curves/unchecked.hpp"
#include "diffusion/dirichlet.hpp"
#include "diffusion/laplace_unchecked.hpp"
#include "diffusion/region_mesh.hpp"

#include <tbb/parallel_for.h>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <tuple>
#include <utility>
#include <vector>

namespace morphomap {

using detail::kNaN;

namespace {

using detail::free_vertex;
using detail::source_vertex;
using detail::target_vertex;

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// The P1 solution on the triangles: local stiffness grad phi_i . grad phi_j * area.
Vector solve_potential(const detail::RegionMesh& mesh, const std::vector<char>& kind) {
  return detail::solve_dirichlet(
      mesh.vertices.rows(), mesh.triangles, kind,
      [&](Index t) {
        Vec2 p[3];
        for (int i = 0; i < 3; ++i) p[i] = mesh.vertices.row(mesh.triangles(t, i)).transpose();
        return detail::triangle_stiffness(p);
      },
      false);
}

// Follows -grad c from a vertex of the source until it meets the target. The P1 gradient is
// constant on each triangle; tracing it exactly is first-order accurate (streamlines zigzag and
// merge along edges). So it is first recovered at the vertices (the area-weighted mean over the
// triangles around each) and interpolated linearly: a continuous flow whose streamlines do not
// cross, second-order accurate, crossed triangle by triangle in RK4 steps of a fraction of the
// triangle's size.
class Tracer {
 public:
  Tracer(const detail::RegionMesh& mesh, const Vector& c, const std::vector<char>& kind)
      : mesh_(mesh),
        c_(c),
        kind_(kind),
        step_(mesh.triangles.rows()),
        to_barycentric_(mesh.triangles.rows()),
        flow_(mesh.triangles.rows()) {
    const Index n = mesh.vertices.rows(), triangles = mesh.triangles.rows();
    detail::CompressedRows around = detail::incident_elements(n, mesh.triangles);
    offsets_ = std::move(around.first);
    incident_ = std::move(around.entries);
    std::vector<double> weight(n, 0.0);
    velocity_.assign(n, Vec2::Zero());
    for (Index t = 0; t < triangles; ++t) {
      Vec2 p[3];
      for (int i = 0; i < 3; ++i) p[i] = point(mesh.triangles(t, i));
      const double area2 = cross(p[1] - p[0], p[2] - p[0]);
      // -grad c = -sum_i c_i grad phi_i, grad phi_i = rot(edge opposite i) / (2 area).
      Vec2 flow = Vec2::Zero();
      double longest = 0.0;
      for (int i = 0; i < 3; ++i) {
        const Vec2 e = p[(i + 2) % 3] - p[(i + 1) % 3];
        flow -= c_[mesh.triangles(t, i)] * Vec2(-e.y(), e.x()) / area2;
        longest = std::max(longest, e.norm());
      }
      for (int i = 0; i < 3; ++i) {
        velocity_[mesh.triangles(t, i)] += area2 * flow;
        weight[mesh.triangles(t, i)] += area2;
      }
      step_[t] = 0.25 * area2 / longest;  // a quarter of the smallest height
      // Barycentric coordinates as an affine map of x: l_i = (cross(p_j - x, p_k - x)) / area2.
      Affine& map = to_barycentric_[t];
      for (int i = 0; i < 3; ++i) {
        const Vec2 pj = p[(i + 1) % 3], pk = p[(i + 2) % 3];
        map.row(i) << (pj.y() - pk.y()) / area2, (pk.x() - pj.x()) / area2, cross(pj, pk) / area2;
      }
    }
    for (Index v = 0; v < n; ++v) velocity_[v] /= weight[v];
    // A vertex all of whose triangles lie flat in c (a corner of a curve that the mesher cut off
    // with points on both its edges: three source vertices) would start no streamline: it takes
    // the mean flow of its neighbours instead.
    const std::vector<Vec2> recovered = velocity_;
    for (Index v = 0; v < n; ++v) {
      if (recovered[v].squaredNorm() > 0.0) continue;
      Vec2 sum = Vec2::Zero();
      for (Index k = offsets_[v]; k < offsets_[v + 1]; ++k) {
        for (int i = 0; i < 3; ++i) sum += recovered[mesh.triangles(incident_[k], i)];
      }
      velocity_[v] = sum;
    }
    // On the curves c is constant, so the flow is normal to them: keep only the normal part of
    // the one-sided average there (the normal from the boundary edges at the vertex).
    std::vector<Vec2> normal(n, Vec2::Zero());
    for (Index t = 0; t < triangles; ++t) {
      for (int i = 0; i < 3; ++i) {
        if (mesh.neighbours(t, i) >= 0) continue;
        const Index a = mesh.triangles(t, (i + 1) % 3), b = mesh.triangles(t, (i + 2) % 3);
        if (kind[a] == free_vertex || kind[a] != kind[b]) continue;
        const Vec2 e = point(b) - point(a);
        normal[a] += Vec2(e.y(), -e.x());
        normal[b] += Vec2(e.y(), -e.x());
      }
    }
    for (Index v = 0; v < n; ++v) {
      if (kind[v] == free_vertex || normal[v].squaredNorm() == 0.0) continue;
      const Vec2 unit = normal[v].normalized();
      velocity_[v] = velocity_[v].dot(unit) * unit;
    }
    for (Index t = 0; t < triangles; ++t) {
      Eigen::Matrix<double, 2, 3> corners;
      for (int i = 0; i < 3; ++i) corners.col(i) = velocity_[mesh.triangles(t, i)];
      flow_[t] = corners * to_barycentric_[t];
    }
    step_limit_ = 40 * (triangles + n) + 1000;
  }

  Vec2 trace(Index start, std::vector<Vec2>* path) const {
    const Vec2 lost(kNaN, kNaN);
    auto record = [&](const Vec2& q) {
      if (path) path->push_back(q);
    };
    Index vertex = start, t = -1;
    Vec2 x = point(start);
    record(x);
    Index steps_here = 0, last_triangle = -1;  // a streamline that stalls in one triangle is lost
    // c falls along a streamline: one that has not gone below its lowest c for kStallSteps steps
    // circles or shuttles between triangles (where the recovered flow turns back), and is lost.
    double lowest = c_[start];
    Index since_lowest = 0;
    for (Index step = 0; step < step_limit_; ++step) {
      if (step % 1024 == 0) detail::check_interrupt();
      if (t >= 0 && t == last_triangle) {
        if (++steps_here > kStallSteps) return lost;
      } else {
        steps_here = 0, last_triangle = t;
      }
      if (t >= 0 && step % 16 == 0) {
        const double here = c_at(t, x);
        if (here < lowest - 1e-12) {
          lowest = here, since_lowest = 0;
        } else if ((since_lowest += 16) > kStallSteps) {
          return lost;
        }
      }
      if (vertex >= 0) {
        if (kind_[vertex] == target_vertex && vertex != start) return point(vertex);
        t = enter(vertex);
        if (t < 0) {
          if (!descend_edge(vertex) && !escape_flat(vertex)) return lost;
          record(point(vertex));
          continue;
        }
        x = point(vertex);
        vertex = -1;
      }
      const double h = step_[t];
      const Vec2 k1 = direction(t, x), k2 = direction(t, x + 0.5 * h * k1), k3 = direction(t, x + 0.5 * h * k2),
                 k4 = direction(t, x + h * k3);
      if (k1.squaredNorm() == 0.0) {  // no flow here: continue from the lowest corner
        vertex = lowest_corner(t);
        if (c_[vertex] >= c_at(t, x)) return lost;
        record(point(vertex));
        continue;
      }
      const Vec2 y = x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
      const Eigen::Vector3d ly = barycentric(t, y);
      if (ly.minCoeff() >= 0.0) {
        x = y;
        record(x);
        continue;
      }
      // The step leaves t: through the edge whose coordinate reaches zero first.
      const Eigen::Vector3d lx = barycentric(t, x);
      int edge = -1;
      double first = 2.0;
      for (int i = 0; i < 3; ++i) {
        if (ly[i] >= 0.0) continue;
        const double s = std::max(lx[i], 0.0) / (std::max(lx[i], 0.0) - ly[i]);
        if (s < first) first = s, edge = i;
      }
      const Vec2 p = x + first * (y - x);
      const Index a = mesh_.triangles(t, (edge + 1) % 3), b = mesh_.triangles(t, (edge + 2) % 3);
      const Index next = mesh_.neighbours(t, edge);
      record(p);
      if (next < 0) {
        if (kind_[a] == target_vertex && kind_[b] == target_vertex) return p;
        vertex = c_[a] <= c_[b] ? a : b;  // a boundary without flux: slide along it downhill
        record(point(vertex));
        continue;
      }
      t = next;
      x = barycentric(t, y).minCoeff() >= 0.0 ? y : p;  // finish the step inside the neighbour
    }
    return lost;
  }

 private:
  Vec2 point(Index v) const { return mesh_.vertices.row(v).transpose(); }

  Eigen::Vector3d barycentric(Index t, const Vec2& x) const {
    return to_barycentric_[t].leftCols<2>() * x + to_barycentric_[t].col(2);
  }

  double c_at(Index t, const Vec2& x) const {
    const Eigen::Vector3d l = barycentric(t, x);
    return l[0] * c_[mesh_.triangles(t, 0)] + l[1] * c_[mesh_.triangles(t, 1)] + l[2] * c_[mesh_.triangles(t, 2)];
  }

  // Unit direction of the recovered flow at x, interpolated on triangle t.
  Vec2 direction(Index t, const Vec2& x) const {
    const Vec2 u = flow_[t].leftCols<2>() * x + flow_[t].col(2);
    const double norm = u.norm();
    return norm > 0.0 ? Vec2(u / norm) : Vec2::Zero();
  }

  Index lowest_corner(Index t) const {
    Index best = mesh_.triangles(t, 0);
    for (int i = 1; i < 3; ++i) {
      if (c_[mesh_.triangles(t, i)] < c_[best]) best = mesh_.triangles(t, i);
    }
    return best;
  }

  // The triangle at a vertex that the flow there points into, or -1.
  Index enter(Index vertex) const {
    const Vec2& g = velocity_[vertex];
    if (g.squaredNorm() == 0.0) return -1;
    for (Index k = offsets_[vertex]; k < offsets_[vertex + 1]; ++k) {
      const Index t = incident_[k];
      int j = 0;
      while (mesh_.triangles(t, j) != vertex) ++j;
      const Vec2 v = point(vertex);
      const Vec2 ea = point(mesh_.triangles(t, (j + 1) % 3)) - v, eb = point(mesh_.triangles(t, (j + 2) % 3)) - v;
      if (cross(ea, g) >= 0.0 && cross(g, eb) >= 0.0) return t;
    }
    return -1;
  }

  // No triangle at the vertex takes the flow: go down the steepest edge.
  bool descend_edge(Index& vertex) const {
    Index best = -1;
    double steepest = 0.0;
    for (Index k = offsets_[vertex]; k < offsets_[vertex + 1]; ++k) {
      const Index t = incident_[k];
      for (int i = 0; i < 3; ++i) {
        const Index w = mesh_.triangles(t, i);
        if (w == vertex) continue;
        const double drop = (c_[vertex] - c_[w]) / (point(w) - point(vertex)).norm();
        if (drop > steepest) steepest = drop, best = w;
      }
    }
    if (best < 0) return false;
    vertex = best;
    return true;
  }

  // A vertex whose triangles are all flat in c (a curve's corner the mesher cut off with points
  // on both of its edges) has no way down: go to the nearest vertex of the same potential,
  // through such flat triangles, from which the flow or an edge leads on.
  bool escape_flat(Index& vertex) const {
    std::vector<Index> queue{vertex};
    for (std::size_t head = 0; head < queue.size() && queue.size() < 256; ++head) {
      const Index v = queue[head];
      for (Index k = offsets_[v]; k < offsets_[v + 1]; ++k) {
        for (int i = 0; i < 3; ++i) {
          const Index w = mesh_.triangles(incident_[k], i);
          if (c_[w] != c_[vertex] || std::find(queue.begin(), queue.end(), w) != queue.end()) continue;
          Index next = w;
          if (enter(w) >= 0 || descend_edge(next)) {
            vertex = w;
            return true;
          }
          queue.push_back(w);
        }
      }
    }
    return false;
  }

  // RK4 steps are a quarter of the smallest height, so a streamline crosses a triangle in a few
  // of them; hundreds mean it has stalled (where the flow vanishes or turns back at a wall).
  static constexpr Index kStallSteps = 1000;
  const detail::RegionMesh& mesh_;
  const Vector& c_;
  const std::vector<char>& kind_;
  std::vector<Vec2> velocity_;  // recovered -grad c at the vertices
  std::vector<double> step_;    // RK4 step length in each triangle
  // Each triangle's barycentric coordinates as an affine map of the point: the tracer evaluates
  // them several times per step, and this saves reading its three corners each time.
  using Affine = Eigen::Matrix<double, 3, 3, Eigen::RowMajor>;
  std::vector<Affine, Eigen::aligned_allocator<Affine>> to_barycentric_;
  // The interpolated flow on each triangle, also affine in the point.
  using AffineFlow = Eigen::Matrix<double, 2, 3>;
  std::vector<AffineFlow, Eigen::aligned_allocator<AffineFlow>> flow_;
  std::vector<Index> offsets_, incident_;
  Index step_limit_ = 0;
};

// Meshing squares lengths: keep them far from overflow and underflow. Diffusion's own rule (the
// mapping does not check it), and the first after require_curve: the other checks square lengths too.
void require_in_range(const Points2Ref& points, Index rows, const char* name) {
  const auto p = points.topRows(rows);
  const double far = p.cwiseAbs().maxCoeff();
  const double extent = (p.colwise().maxCoeff() - p.colwise().minCoeff()).norm();
  if (!(far <= 1e100) || !(extent >= 1e-100)) {
    detail::invalid(name,
                    "diffusion mapping needs coordinates within 1e100 of the origin and a curve "
                    "wider than 1e-100 (rescale the curves)");
  }
}

DiffusionSolution solve(const Points2Ref& source_points, const Points2Ref& target_points, bool closed,
                        const DiffusionOptions& options, double vertex_budget);

}  // namespace

void detail::require_diffusion_curves(const Points2Ref& source_points, const Points2Ref& target_points, bool closed) {
  const Index ns = detail::require_curve(source_points, closed, "c1");
  const Index nt = detail::require_curve(target_points, closed, "c2");
  require_in_range(source_points, ns, "c1");
  require_in_range(target_points, nt, "c2");
  // The region between the curves is only defined for simple ones.
  detail::require_no_self_intersection(source_points.topRows(ns), closed, "c1");
  detail::require_no_self_intersection(target_points.topRows(nt), closed, "c2");
  if (closed) {
    detail::require_area(source_points.topRows(ns), "c1");
    detail::require_area(target_points.topRows(nt), "c2");
  }
}

DiffusionSolution solve_diffusion(const Points2Ref& source_points, const Points2Ref& target_points, bool closed,
                                  const DiffusionOptions& options) {
  detail::require_diffusion_curves(source_points, target_points, closed);
  detail::require_diffusion_options(options);
  return solve(source_points, target_points, closed, options, 0.0);
}

DiffusionSolution detail::solve_diffusion_unchecked(const Points2Ref& source_points, const Points2Ref& target_points,
                                                    bool closed, const DiffusionOptions& options,
                                                    double vertex_budget) {
  require_in_range(source_points, curve_size(source_points, closed), "c1");
  require_in_range(target_points, curve_size(target_points, closed), "c2");
  return solve(source_points, target_points, closed, options, vertex_budget);
}

namespace {

// solve_diffusion on checked curves and options.
DiffusionSolution solve(const Points2Ref& source_points, const Points2Ref& target_points, bool closed,
                        const DiffusionOptions& options, double vertex_budget) {
  const Index ns = detail::curve_size(source_points, closed);
  const Index nt = detail::curve_size(target_points, closed);
  const Points2 source = source_points.topRows(ns), target = target_points.topRows(nt);

  // Boundary loops; input points are numbered source first, then target.
  std::vector<Points2> loops;
  bool crossing = false;
  bool same_start = false, same_end = false;  // open curves: they share an end point
  if (closed) {
    crossing = detail::curve_intersections_unchecked(source, target, true).points.rows() > 0;
    if (!crossing && !detail::inside(source.row(0).transpose(), target) &&
        !detail::inside(target.row(0).transpose(), source)) {
      detail::invalid("c2", "diffusion mapping needs one curve inside the other, or crossing curves");
    }
    loops = {source, target};
  } else {
    // source forwards, then target backwards; shared end points (crossings) appear once. Ends within
    // rounding of each other are one point: the joining edge of 1e-16 they would leave crashed
    // the 2D mesher.
    const double extent = (source.colwise().maxCoeff() - source.colwise().minCoeff()).norm() +
                          (target.colwise().maxCoeff() - target.colwise().minCoeff()).norm();
    const double rounding = 1e-12 * extent;
    same_start = (source.row(0) - target.row(0)).norm() <= rounding;
    same_end = (source.row(ns - 1) - target.row(nt - 1)).norm() <= rounding;
    const Index t_begin = same_start ? 1 : 0, t_end = same_end ? nt - 1 : nt;
    Points2 loop(ns + (t_end - t_begin), 2);
    loop.topRows(ns) = source;
    for (Index i = t_end - 1, r = ns; i >= t_begin; --i, ++r) loop.row(r) = target.row(i);
    loops = {loop};
  }

  using Clock = std::chrono::steady_clock;
  auto seconds_since = [](Clock::time_point start) {
    return std::chrono::duration<double>(Clock::now() - start).count();
  };
  DiffusionSolution solution;
  auto clock = Clock::now();
  double max_edge = options.mesh_size;
  if (max_edge == 0.0) {
    // Mean gap: twice the region's area over its boundary length. The region of closed curves is
    // their symmetric difference (an annulus when nested); of open ones, the loop that joins them.
    double area = 0.0;
    if (closed) {
      const double a1 = std::abs(detail::signed_area_unchecked(source)),
                   a2 = std::abs(detail::signed_area_unchecked(target));
      area = crossing ? a1 + a2 - 2.0 * overlap_area(source, target) : std::abs(a1 - a2);
    } else {
      area = std::abs(signed_area(loops[0]));  // a new curve: checked here
    }
    const double boundary = detail::perimeter_unchecked(source, closed) + detail::perimeter_unchecked(target, closed);
    // A long thin region (a piece between two contact stretches, say) would get length / gap
    // times the vertices of a round one of the same gap: the lattice is kept within a budget of
    // vertices (detail::vertex_budget: at 20 per curve point, 40000 at least), still 20 or more
    // across such a gap. A piece of a split pair gets its share of the pair's budget.
    const double budget = vertex_budget > 0.0 ? vertex_budget : detail::vertex_budget(ns + nt);
    const double coarsest = std::sqrt(2.0 / std::sqrt(3.0) * area / budget);
    max_edge = std::max(options.mesh_fraction * 2.0 * area / boundary, coarsest);
  }
  const detail::RegionMesh mesh = detail::mesh_region(loops, max_edge);
  if (mesh.triangles.rows() == 0) throw GeometryError("the region between the curves is empty");
  solution.mesh_seconds = seconds_since(clock);
  clock = Clock::now();

  // Dirichlet vertices: the input points, and the points the mesher added on the curves.
  const Index nv = mesh.vertices.rows();
  std::vector<char> kind(nv, free_vertex);
  const CurveIndex on_source = detail::CurveIndexUnchecked::build(source, closed);
  const CurveIndex on_target = detail::CurveIndexUnchecked::build(target, closed);
  const double scale = (mesh.vertices.colwise().maxCoeff() - mesh.vertices.colwise().minCoeff()).norm();
  const double tolerance = 1e-10 * scale;
  std::vector<Index> added;  // boundary vertices the mesher added: on which curve, found below
  for (Index v = 0; v < nv; ++v) {
    const Index input = mesh.input[v];
    if (input >= 0) {
      kind[v] = input < ns ? source_vertex : target_vertex;
      if (!closed && input < ns && ((input == 0 && same_start) || (input == ns - 1 && same_end))) {
        kind[v] = target_vertex;  // a shared end point: already on the target
      }
    } else if (mesh.on_boundary[v]) {
      added.push_back(v);
    }
  }
  // One batch query per curve (the index runs it on all cores).
  Points2 added_points(static_cast<Index>(added.size()), 2);
  for (std::size_t k = 0; k < added.size(); ++k) added_points.row(static_cast<Index>(k)) = mesh.vertices.row(added[k]);
  detail::check_interrupt();
  const Vector to_source = detail::CurveIndexUnchecked::closest_points(on_source, added_points).distances;
  const Vector to_target = detail::CurveIndexUnchecked::closest_points(on_target, added_points).distances;
  for (std::size_t k = 0; k < added.size(); ++k) {
    const Index row = static_cast<Index>(k);
    if (to_target[row] <= tolerance)
      kind[added[k]] = target_vertex;
    else if (to_source[row] <= tolerance)
      kind[added[k]] = source_vertex;
  }

  solution.potential = solve_potential(mesh, kind);
  solution.solve_seconds = seconds_since(clock);
  clock = Clock::now();
  const Tracer tracer(mesh, solution.potential, kind);
  solution.ends.resize(ns, 2);
  if (options.keep_streamlines) solution.streamlines.resize(ns);
  // Source points where no streamline starts, and their distance to the target (one batch).
  std::vector<Index> unstarted;
  for (Index i = 0; i < ns; ++i) {
    const Index start = mesh.of_input[i];
    if (start < 0 || kind[start] == target_vertex) unstarted.push_back(i);
  }
  Points2 unstarted_points(static_cast<Index>(unstarted.size()), 2);
  for (std::size_t k = 0; k < unstarted.size(); ++k)
    unstarted_points.row(static_cast<Index>(k)) = source.row(unstarted[k]);
  const Vector unstarted_to_target = detail::CurveIndexUnchecked::closest_points(on_target, unstarted_points).distances;
  std::vector<char> on_target_already(ns, 0);
  for (std::size_t k = 0; k < unstarted.size(); ++k) {
    on_target_already[unstarted[k]] = unstarted_to_target[static_cast<Index>(k)] <= tolerance;
  }
  tbb::parallel_for(Index(0), ns, [&](Index i) {
    std::vector<Vec2> path;
    // A point of C1 that bounds no part of the region (where the curves run together) or lies
    // on C2 already stays where it is if it is on C2; streamlines start at the others.
    const Index start = mesh.of_input[i];
    const Vec2 here = source.row(i).transpose();
    Vec2 end(kNaN, kNaN);
    if (start < 0 || kind[start] == target_vertex) {
      if (on_target_already[i]) end = here;
    } else {
      end = tracer.trace(start, options.keep_streamlines ? &path : nullptr);
    }
    solution.ends.row(i) = end.transpose();
    if (options.keep_streamlines) {
      if (path.empty()) path.push_back(end);
      Points2 line(path.size(), 2);
      for (std::size_t k = 0; k < path.size(); ++k) line.row(k) = path[k].transpose();
      solution.streamlines[i] = std::move(line);
    }
  });
  solution.trace_seconds = seconds_since(clock);
  solution.vertices = mesh.vertices;
  solution.triangles = mesh.triangles;
  return solution;
}

}  // namespace

}  // namespace morphomap
