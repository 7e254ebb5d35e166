// The monotone matching behind method "optimal": the problem and its levels set up, solved
// (optimal_levels.cpp) inside the region between the pieces, and checked for crossings.
#include <morphomap/crossings.hpp>
#include <morphomap/curve_queries.hpp>
#include <morphomap/optimal.hpp>

#include "common/numbers.hpp"
#include "common/validation.hpp"
#include "curves/arc_curve.hpp"
#include "curves/crossing_sweep.hpp"
#include "curves/unchecked.hpp"
#include "mapping/match_region.hpp"
#include "mapping/optimal_levels.hpp"
#include "mapping/optimal_unchecked.hpp"

#include <morphomap/errors.hpp>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>
#include <vector>

namespace morphomap {

using detail::kInf;

namespace {

using detail::ArcCurve;
using detail::MatchProblem;
using detail::MatchRegion;
constexpr Index kThinning = 4;  // starts per level
// The full grid (every sample for every start, about 5 R^2 cells for R starts, each a line query
// with the region) is searched for at most kCoarsest starts; larger problems are thinned level by
// level down to that. A full grid of 256 rows outweighed all finer levels together (the default on
// limb 330->381 h closed at 10^4 points: 1.7 s with it, 1.2 s without), and with kSmallMatch's
// margins the 200-point outlines keep every QM (bench/README.md "Real 2D outlines").
constexpr Index kCoarsest = 64;
// A target with an edge longer than this many times its median edge is sampled through its
// vertices as well as evenly (sample_arcs).
constexpr double kUneven = 4.0;

// Where the source doubles back next to a piece's end (a traced tip whose last point lies back
// across the one before it), every strictly increasing path crosses that end's vector: a
// crossing-free order-preserving field exists only with the rows between sharing its end point.
// For each crossing pair of rows a < b of which one is fixed (a pinned row, or an end vector as
// row -1 or n; `starts` holds the starts and then the end vectors, in virtual_rows' order), the
// free rows from the other one up to it take its end, if that leaves fewer crossings; the ends
// then increase along the target but not strictly there. Crossings among free rows are left (a
// field that collapsed them would not be the bijective matching optimal.hpp promises). Returns
// the crossings left.
Index merge_crossing_ends(const MatchProblem& p, const Points2& starts, const std::vector<Index>& virtual_rows,
                          MonotoneMatch& match) {
  const Index n = match.points.rows();
  auto fixed = [&](Index r) { return r < 0 || r >= n || (r == 0 && p.pinned_first) || (r == n - 1 && p.pinned_last); };
  auto end_of = [&](Index r) -> std::pair<double, Vec2> {
    if (r < 0) return {0.0, p.begin_target};
    if (r >= n) return {p.target_length, p.end_target};
    return {match.arcs[r], match.points.row(r).transpose()};
  };
  auto ends_of = [&](const MonotoneMatch& m) {
    Points2 ends(starts.rows(), 2);
    ends.topRows(n) = m.points;
    for (std::size_t e = 0; e < virtual_rows.size(); ++e) {
      ends.row(n + static_cast<Index>(e)) = (virtual_rows[e] < 0 ? p.begin_target : p.end_target).transpose();
    }
    return ends;
  };
  auto row_of = [&](Index index) { return index < n ? index : virtual_rows[index - n]; };
  std::vector<std::pair<Index, Index>> pairs = crossing_pairs(starts, ends_of(match));
  while (!pairs.empty()) {
    Index left = static_cast<Index>(pairs.size());
    MonotoneMatch chosen;
    for (const auto& [i, j] : pairs) {
      const Index a = std::min(row_of(i), row_of(j)), b = std::max(row_of(i), row_of(j));
      for (const bool forward : {true, false}) {
        if (forward ? fixed(a) || !fixed(b) : fixed(b) || !fixed(a)) continue;
        MonotoneMatch merged = match;
        const auto [arc, point] = end_of(forward ? b : a);
        for (Index r = forward ? a : a + 1; r <= (forward ? b - 1 : b); ++r) {
          if (r < 0 || r >= n) continue;
          merged.arcs[r] = arc;
          merged.points.row(r) = point.transpose();
        }
        const Index count = count_crossings(starts, ends_of(merged));
        if (count < left) left = count, chosen = std::move(merged);
      }
      if (left == 0) break;
    }
    if (left == static_cast<Index>(pairs.size())) break;  // no merge helps
    match = std::move(chosen);
    match.by_construction = false;
    pairs = crossing_pairs(starts, ends_of(match));
  }
  return static_cast<Index>(pairs.size());
}

}  // namespace

MonotoneMatch monotone_match(const Points2Ref& source, const std::vector<Index>& start_rows, const Points2Ref& target,
                             double stretch_weight) {
  if (!(stretch_weight >= 0.0) || !std::isfinite(stretch_weight)) {
    detail::invalid("stretch_weight", "must be a finite number >= 0, got " + std::to_string(stretch_weight));
  }
  if (source.rows() < 2) detail::invalid("source", "needs at least 2 points");
  if (target.rows() < 2) detail::invalid("target", "needs at least 2 points");
  if (!source.allFinite()) detail::invalid("source", "has a non-finite coordinate");
  if (!target.allFinite()) detail::invalid("target", "has a non-finite coordinate");
  for (std::size_t r = 0; r < start_rows.size(); ++r) {
    if (start_rows[r] < 0 || start_rows[r] >= source.rows() || (r > 0 && start_rows[r] <= start_rows[r - 1])) {
      detail::invalid("start_rows", "must be increasing rows of source");
    }
  }
  return detail::monotone_match_unchecked(source, start_rows, target, stretch_weight);
}

MonotoneMatch detail::monotone_match_unchecked(const Points2Ref& source, const std::vector<Index>& start_rows,
                                               const Points2Ref& target, double stretch_weight) {
  const Index n = static_cast<Index>(start_rows.size());
  MonotoneMatch match;
  match.arcs.resize(n);
  match.points.resize(n, 2);
  if (n == 0) return match;

  // Arc positions along both open polylines (repeated points kept: the pieces may touch).
  Vector source_arc(source.rows());
  source_arc[0] = 0.0;
  for (Index i = 1; i < source.rows(); ++i)
    source_arc[i] = source_arc[i - 1] + (source.row(i) - source.row(i - 1)).norm();
  double target_length = 0.0;
  for (Index i = 1; i < target.rows(); ++i) target_length += (target.row(i) - target.row(i - 1)).norm();
  if (!(target_length > 0.0)) {  // a target piece shrunk to a point takes every start
    match.arcs.setZero();
    match.points = target.row(0).replicate(n, 1);
    return match;
  }
  // Finite, 2 points or more (checked by the caller) and of non-zero length: the unchecked forms.
  const ArcCurve curve = ArcCurve::unchecked(target, false);

  MatchProblem p;
  p.starts = source(start_rows, Eigen::all);
  p.s = source_arc(start_rows);
  p.source_length = source_arc[source.rows() - 1];
  p.target_length = curve.length();
  p.begin_source = source.row(0).transpose(), p.end_source = source.row(source.rows() - 1).transpose();
  p.begin_target = target.row(0).transpose(), p.end_target = target.row(target.rows() - 1).transpose();
  p.pinned_first = start_rows.front() == 0;
  p.pinned_last = start_rows.back() == source.rows() - 1 && !(n == 1 && p.pinned_first);
  p.stretch_weight = stretch_weight;
  p.alpha = p.source_length > 0.0 ? p.target_length / p.source_length : 1.0;
  p.target = &curve;
  p.vertex_arcs.assign(target.rows(), 0.0);
  std::vector<double> edges(target.rows() - 1);
  for (Index i = 1; i < target.rows(); ++i) {
    edges[i - 1] = (target.row(i) - target.row(i - 1)).norm();
    p.vertex_arcs[i] = p.vertex_arcs[i - 1] + edges[i - 1];
  }
  const double longest = *std::max_element(edges.begin(), edges.end());
  std::nth_element(edges.begin(), edges.begin() + edges.size() / 2, edges.end());
  p.uneven_target = longest > kUneven * edges[edges.size() / 2];
  using Unchecked = detail::CurveIndexUnchecked;
  const double gap2 =
      Unchecked::closest_points(Unchecked::build(target, false), p.starts).distances.array().square().mean();
  const double spacing = p.source_length / static_cast<double>(n + 1);
  const double scale = std::max({gap2, spacing * spacing, 1e-300});
  p.displacement_weight = 1.0 / scale;

  const Index finest = std::max(4 * (n + 1), std::min<Index>(target.rows(), 8 * (n + 1)));
  match.samples = finest;

  // The levels, finest first: every kThinning-th start of the level below (the pinned ends kept).
  std::vector<std::vector<Index>> levels{std::vector<Index>(n)};
  for (Index r = 0; r < n; ++r) levels[0][r] = r;
  while (static_cast<Index>(levels.back().size()) > kCoarsest) {
    const std::vector<Index>& below = levels.back();
    std::vector<Index> rows;
    for (std::size_t r = 0; r < below.size(); r += kThinning) rows.push_back(below[r]);
    if (p.pinned_last && rows.back() != n - 1) rows.push_back(n - 1);
    levels.push_back(std::move(rows));
  }

  // The pieces' end vectors not among the starts' own, for the crossing count (once where they
  // are one, as on a cut ring).
  std::vector<Vec2> from, to;
  if (!p.pinned_first) from.push_back(p.begin_source), to.push_back(p.begin_target);
  const bool one_vector = p.end_source == p.begin_source && p.end_target == p.begin_target;
  if (!p.pinned_last && !one_vector) from.push_back(p.end_source), to.push_back(p.end_target);
  Points2 starts(n + static_cast<Index>(from.size()), 2);
  starts.topRows(n) = p.starts;
  for (std::size_t e = 0; e < from.size(); ++e) starts.row(n + static_cast<Index>(e)) = from[e].transpose();
  // Row of the path that each vector after the n starts' own stands for: -1 before the first, n
  // after the last.
  std::vector<Index> virtual_rows;
  if (!p.pinned_first) virtual_rows.push_back(-1);
  if (!p.pinned_last && !one_vector) virtual_rows.push_back(n);
  // The path's ends into match (fill), and an exact count of their crossings, or (exact false) 1
  // where they have any (take).
  std::vector<double> coarse_t;
  double energy = 0.0;
  auto fill = [&] {
    for (Index r = 0; r < n; ++r) {
      match.arcs[r] = coarse_t[r];
      match.points.row(r) = curve.point_at(coarse_t[r]).transpose();
    }
    if (p.pinned_first) match.points.row(0) = p.begin_target.transpose();
    if (p.pinned_last) match.points.row(n - 1) = p.end_target.transpose();
    match.energy = energy;
  };
  auto take = [&](bool exact) -> Index {
    fill();
    Points2 ends(starts.rows(), 2);
    ends.topRows(n) = match.points;
    for (std::size_t e = 0; e < to.size(); ++e) ends.row(n + static_cast<Index>(e)) = to[e].transpose();
    if (exact) return count_crossings(starts, ends);
    return detail::any_crossing(starts, ends) ? 1 : 0;
  };

  // With the region: crossing-free by construction where it is a simple polygon (or the cut ring);
  // where it is not, its vectors are still the likeliest to be free of crossings. Without a path
  // inside it, the penalised one. Every result is checked exactly (the line queries round at 1e-9
  // of a vector's length) and returned only without crossings.
  const bool free_rows = n > static_cast<Index>(p.pinned_first) + static_cast<Index>(p.pinned_last);
  std::unique_ptr<MatchRegion> region;
  std::string why_not;
  Index crossings = 0;
  bool inside = false, jumped = false;
  if (free_rows) {
    region = std::make_unique<MatchRegion>(source, target);
    why_not = region->why_not();
    p.region = region.get();
    inside = solve_levels(p, levels, finest, start_rows, coarse_t, energy, jumped);
    if (inside) crossings = take(false);
  } else {
    solve_levels(p, levels, finest, start_rows, coarse_t, energy, jumped);
    crossings = take(true);
  }
  match.by_construction = inside && why_not.empty() && crossings == 0;
  if (inside && crossings == 0 && jumped && n <= detail::kSmallMatch) {
    // A forced jump is one long stretch; the penalised matching, whose vectors may leave the
    // region a little, may still be crossing-free and spread it (limb 252->256 h open, mapped
    // back: QM 0.0036 with the jump, 0.00028 without). The lower energy without crossings wins.
    // Only on small problems: on the limb and kidney pairs resampled to 10^3-10^4 points it won
    // none of 9 tries (its vectors cross by the hundred there) and doubled optimal's time.
    p.region = nullptr;  // not needed again: this path is crossing-free either way
    std::vector<double> kept_t = coarse_t;
    const double kept_energy = energy;
    bool ignored = false;
    try {
      solve_levels(p, levels, finest, start_rows, coarse_t, energy, ignored);
    } catch (const GeometryError&) {
      energy = kInf;
    }
    if (energy < kept_energy && take(false) == 0) {
      match.by_construction = false;
    } else {
      coarse_t = std::move(kept_t), energy = kept_energy;
      fill();
    }
  }
  if (free_rows && (!inside || crossings > 0)) {
    if (why_not.empty()) {
      why_not = inside ? "the vectors inside the region cross by rounding"
                       : "no path of vectors inside the region between them was found at the matching's sampling";
    }
    p.region = nullptr;
    solve_levels(p, levels, finest, start_rows, coarse_t, energy, jumped);
    crossings = take(true);
  }
  if (crossings > 0) crossings = merge_crossing_ends(p, starts, virtual_rows, match);
  if (crossings > 0) {
    throw GeometryError("optimal: no crossing-free order-preserving matching of a pair of pieces (" +
                        (why_not.empty() ? std::string("its ends are fixed") : why_not) +
                        "; the matching without that constraint has " + std::to_string(crossings) +
                        " crossing pairs); method 'best' keeps the best crossing-free candidate");
  }
  return match;
}

}  // namespace morphomap
