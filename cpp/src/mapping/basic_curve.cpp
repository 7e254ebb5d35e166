// The basic algorithms on one job of map_curves (curve_job.hpp): minimal distance, normal,
// uniform, diffusion and optimal, forward and reversed, and the anchors of uniform and optimal
// mapping of closed curves.
#include <morphomap/curve_geometry.hpp>
#include <morphomap/curve_queries.hpp>
#include <morphomap/laplace.hpp>
#include <morphomap/optimal.hpp>

#include "common/finite_rows.hpp"
#include "common/numbers.hpp"
#include "common/validation.hpp"
#include "curves/arc_curve.hpp"
#include "curves/unchecked.hpp"
#include "diffusion/laplace_unchecked.hpp"
#include "mapping/curve_job.hpp"
#include "mapping/optimal_unchecked.hpp"

#include <unsupported/Eigen/FFT>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <string>
#include <vector>

namespace morphomap::detail {

namespace {

using Unchecked = CurveIndexUnchecked;

bool all_rows_equal(const Points2& points) {
  for (Index i = 1; i < points.rows(); ++i) {
    if (points.row(i) != points.row(0)) return false;
  }
  return true;
}

// Streamlines of one flow do not cross, but two that run a hair apart can come out swapped by
// rounding and step error (seen where they converge onto a small curve): the ends, taken in the
// order of their start points, are put back in order along the target, the set of ends kept.
// Positions are unrolled step by step (the shorter way between neighbours on a closed curve), so
// only local swaps move.
void put_in_order(Points2& ends, const ArcCurve& target, const CurveIndex& target_index) {
  const std::vector<Index> rows = detail::finite_rows(ends);
  if (rows.size() < 2) return;
  const Points2 found = ends(rows, Eigen::all);
  const Vector arcs = Unchecked::closest_points(target_index, found).arc_lengths;
  const double length = target.length();
  std::vector<double> unrolled(rows.size(), 0.0);
  for (std::size_t k = 1; k < rows.size(); ++k) {
    double step = arcs[k] - arcs[k - 1];
    if (target.closed()) step -= length * std::round(step / length);
    unrolled[k] = unrolled[k - 1] + step;
  }
  const double direction = unrolled.back() >= 0.0 ? 1.0 : -1.0;
  for (double& u : unrolled) u *= direction;
  if (std::is_sorted(unrolled.begin(), unrolled.end())) return;
  std::sort(unrolled.begin(), unrolled.end());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    ends.row(rows[k]) = target.point_at(arcs[0] + direction * unrolled[k]).transpose();
  }
}

// A closed curve cut open at arc position a: from the point there once round back to it.
Points2 cut_open(const ArcCurve& curve, double a) {
  a = curve.wrap(a);
  std::vector<Vec2> rows{curve.point_at(a)};
  for (Index v = 0; v < curve.size(); ++v) {
    if (curve.arc(v) > a) rows.push_back(curve.points().row(v).transpose());
  }
  for (Index v = 0; v < curve.size(); ++v) {
    if (curve.arc(v) < a) rows.push_back(curve.points().row(v).transpose());
  }
  rows.push_back(rows.front());
  Points2 out(rows.size(), 2);
  for (std::size_t r = 0; r < rows.size(); ++r) out.row(r) = rows[r].transpose();
  return out;
}

// best_anchor's shift to within a hair: it is found on a grid of m samples, and a pinned start
// point that is off by a fraction of a sample turns the whole matching by that much. Golden-section
// search of the same sum of squared displacements over one grid step either side.
double refined_anchor(const ArcCurve& source, const ArcCurve& target, double anchor) {
  Index m = 64;
  while (m < 2 * source.size()) m *= 2;
  std::vector<Vec2> s(m);
  for (Index j = 0; j < m; ++j) s[j] = source.point_at(source.length() * j / m);
  auto cost = [&](double a) {
    double sum = 0.0;
    for (Index j = 0; j < m; ++j) sum += (s[j] - target.point_at(a + target.length() * j / m)).squaredNorm();
    return sum;
  };
  const double ratio = 0.5 * (std::sqrt(5.0) - 1.0), bin = target.length() / m;
  double lo = anchor - bin, hi = anchor + bin;
  double x1 = hi - ratio * (hi - lo), x2 = lo + ratio * (hi - lo), f1 = cost(x1), f2 = cost(x2);
  for (int iteration = 0; iteration < 20; ++iteration) {  // 0.618^20: 1e-4 of a step
    if (f1 < f2) {
      hi = x2, x2 = x1, f2 = f1, x1 = hi - ratio * (hi - lo), f1 = cost(x1);
    } else {
      lo = x1, x1 = x2, f1 = f2, x2 = lo + ratio * (hi - lo), f2 = cost(x2);
    }
  }
  const double best = 0.5 * (lo + hi);
  return cost(best) <= cost(anchor) ? best : anchor;
}

// "optimal" on one job. A piece (or open curves) is matched between its two ends. Whole closed
// curves are cut open at the first start point and at the point of the target that the best
// cyclic shift puts there (best_anchor), matched once round, then cut again at the start point
// half way round and where the first matching took it, and matched again, so that the pinned
// point of the first pass is free in the second; the lower energy wins.
Points2 optimal_ends(const Job& job, double stretch_weight) {
  if (!job.source_closed) {
    return detail::monotone_match_unchecked(job.source, job.start_rows, job.target, stretch_weight).points;
  }
  const ArcCurve source = ArcCurve::unchecked(job.source, true);
  const ArcCurve given = ArcCurve::unchecked(job.target, true);
  const ArcCurve target = ArcCurve::unchecked(
      relative_direction(source, given) > 0 ? given.points() : Points2(given.points().colwise().reverse()), true);
  const Index n = source.size();
  const Index count = static_cast<Index>(job.start_rows.size());
  auto pass = [&](Index first, double anchor, MonotoneMatch& match) {
    const Index h = job.start_rows[first];
    Points2 rotated(n + 1, 2);
    for (Index j = 0; j <= n; ++j) rotated.row(j) = source.points().row((h + j) % n);
    std::vector<Index> rows(count);
    for (Index k = 0; k < count; ++k) rows[k] = (job.start_rows[(first + k) % count] - h + n) % n;
    match = detail::monotone_match_unchecked(rotated, rows, cut_open(target, anchor), stretch_weight);
    Points2 ends(count, 2);
    for (Index k = 0; k < count; ++k) ends.row((first + k) % count) = match.points.row(k);
    return ends;
  };
  MonotoneMatch first, second;
  const double anchor = refined_anchor(source, target, best_anchor(source, target, 1)) +
                        source.arc(job.start_rows[0]) * target.length() / source.length();
  Points2 ends = pass(0, anchor, first);
  if (count < 2) return ends;
  const Index half = count / 2;
  Points2 other = pass(half, anchor + first.arcs[half], second);
  return second.energy < first.energy ? other : ends;
}

Points2 basic_ends(MapMethod method, const Job& job, const Points2& starts, const Settings& settings) {
  if (starts.rows() == 0) return Points2(0, 2);
  // A piece of the target that shrank to a point (two meetings at one place) takes all starts.
  if (all_rows_equal(job.target)) return job.target.row(0).replicate(starts.rows(), 1);
  const ArcCurve target = ArcCurve::unchecked(job.target, job.target_closed);
  switch (method) {
    case MapMethod::minimal_distance:
      return Unchecked::closest_points(target_index(job), starts).points;
    case MapMethod::normal:  // unit normals
      return Unchecked::line_intersections(target_index(job), starts, job.normals).points;
    case MapMethod::uniform: {
      Points2 ends(starts.rows(), 2);
      for (Index i = 0; i < ends.rows(); ++i) {
        const double s = job.anchor + job.direction * job.fractions[i] * target.length();
        ends.row(i) = target.point_at(s).transpose();
      }
      return ends;
    }
    case MapMethod::diffusion: {
      if (!settings.simple_curves) detail::require_diffusion_curves(job.source, job.target, job.source_closed);
      const DiffusionSolution solution = detail::solve_diffusion_unchecked(
          job.source, job.target, job.source_closed, settings.diffusion,
          detail::piece_vertex_budget(job.source.rows() + job.target.rows(), settings.pair_points));
      Points2 ends(starts.rows(), 2);
      for (std::size_t j = 0; j < job.start_rows.size(); ++j) ends.row(j) = solution.ends.row(job.start_rows[j]);
      put_in_order(ends, target, target_index(job));
      return ends;
    }
    case MapMethod::optimal:
      return optimal_ends(job, settings.stretch_weight);
    case MapMethod::automatic:
    case MapMethod::paper:
      break;
  }
  detail::invalid("method", "not a basic algorithm");
}

}  // namespace

Method basic_method(MapMethod method) {
  const MethodRow& row = method_row(method);
  if (!row.forward) detail::invalid("method", std::string("'") + row.name + "' is not a basic algorithm");
  return *row.forward;
}

// A basic algorithm on one job, from its start points.
Vectors forward(MapMethod method, const Job& job, const std::vector<double>& start_keys, const Settings& settings) {
  Vectors v;
  v.starts = start_points(job);
  v.keys = start_keys;
  v.ends = basic_ends(method, job, v.starts, settings);
  v.methods.assign(v.starts.rows(), basic_method(method));
  return v;
}

// A basic algorithm run backwards on one job (the paper's reverse mapping): from the target's
// points (but shared crossings) to the source, flipped.
Vectors reverse(MapMethod method, const Job& job, const ArcCurve& whole_source, const CurveIndex& whole_source_index,
                const Settings& settings) {
  Job back;
  back.source = job.target;
  back.source_closed = job.target_closed;
  back.target = job.source;
  back.target_closed = job.source_closed;
  back.source_index = job.target_index;
  back.target_index = job.source_index;
  const Index n = job.target.rows();
  for (Index i = 0; i < n; ++i) {
    const bool shared =
        !job.target_closed &&
        ((i == 0 && (job.shared_begin || job.target.row(0) == job.source.row(0))) ||
         (i == n - 1 && (job.shared_end || job.target.row(n - 1) == job.source.row(job.source.rows() - 1))));
    if (!shared) back.start_rows.push_back(i);
  }
  Vectors v;
  v.ends = start_points(back);
  if (method == MapMethod::normal) {
    back.normals = detail::normals_unchecked(back.source, back.source_closed)(back.start_rows, Eigen::all);
  }
  v.starts = basic_ends(method, back, v.ends, settings);
  job.source_index = back.target_index, job.target_index = back.source_index;  // for the next attempt
  v.methods.assign(v.starts.rows(), reversed(basic_method(method)));
  v.keys.assign(v.starts.rows(), std::numeric_limits<double>::infinity());
  const std::vector<Index> found = detail::finite_rows(v.starts);
  if (!found.empty()) {
    const Points2 located = v.starts(found, Eigen::all);
    const Vector arcs = Unchecked::closest_points(whole_source_index, located).arc_lengths;
    for (std::size_t j = 0; j < found.size(); ++j) v.keys[found[j]] = whole_source.wrap(arcs[j]);
  }
  // A miss keeps its point on the target (ends), so that it can be found; its start is NaN.
  for (Index i = 0; i < v.starts.rows(); ++i) {
    if (!v.starts.row(i).allFinite()) v.starts.row(i).setConstant(kNaN);
  }
  return v;
}

// Closed curves without a known pair of anchors: the start of the target (walking in direction)
// such that equally spaced points of both curves, matched in order, are closest in the sum of
// squared displacements. A circular cross-correlation by FFT over 2^k samples.
double best_anchor(const ArcCurve& source, const ArcCurve& target, int direction) {
  Index m = 64;
  while (m < 2 * source.size()) m *= 2;
  std::vector<std::complex<double>> s(m), t(m), fs, ft, product(m), correlation;
  for (Index j = 0; j < m; ++j) {
    const Vec2 p = source.point_at(source.length() * j / m);
    const Vec2 q = target.point_at(direction * target.length() * j / m);
    s[j] = {p.x(), p.y()};
    t[j] = {q.x(), q.y()};
  }
  Eigen::FFT<double> fft;
  fft.fwd(fs, s);
  fft.fwd(ft, t);
  for (Index j = 0; j < m; ++j) product[j] = std::conj(fs[j]) * ft[j];
  fft.inv(correlation, product);
  // sum_i |s_i - t_{i+k}|^2 is smallest where Re sum_i conj(s_i) t_{i+k} is largest.
  Index best = 0;
  for (Index k = 1; k < m; ++k) {
    if (correlation[k].real() > correlation[best].real()) best = k;
  }
  return direction * target.length() * best / m;
}

// +1 when both closed curves turn the same way.
int relative_direction(const ArcCurve& source, const ArcCurve& target) {
  return detail::orientation_unchecked(source.points()) == detail::orientation_unchecked(target.points()) ? 1 : -1;
}

}  // namespace morphomap::detail
