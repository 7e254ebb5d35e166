// The monotone matching behind method "optimal": dynamic programming over start points x target
// samples, coarse to fine with a band around the coarser path.
#include <morphomap/crossings.hpp>
#include <morphomap/curve_queries.hpp>
#include <morphomap/optimal.hpp>

#include "common/interrupt_check.hpp"
#include "common/numbers.hpp"
#include "common/validation.hpp"
#include "curves/arc_curve.hpp"
#include "curves/unchecked.hpp"
#include "mapping/match_region.hpp"
#include "mapping/optimal_unchecked.hpp"

#include <morphomap/errors.hpp>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <string>
#include <vector>

namespace morphomap {

using detail::kInf;

namespace {

using detail::ArcCurve;
using detail::MatchRegion;
constexpr double kCrossing = 1e6;  // without the region: added where two close vectors cross
constexpr Index kThinning = 4;     // starts per level
constexpr Index kCoarsest = 256;   // the full grid is searched at or below this many starts
constexpr Index kRecent = 3;       // vectors back along the path checked for crossings
constexpr Index kWidenings = 2;    // with the region: doublings of a level's band before giving up
// A target with an edge longer than this many times its median edge is sampled through its
// vertices as well as evenly (sample_arcs).
constexpr double kUneven = 4.0;

// The problem of one call: start points with their arc positions, the two pieces' lengths, the
// virtual vectors at both ends, and the weights.
struct Problem {
  Points2 starts;
  Vector s;  // arc position of each start along the source
  double source_length = 0.0, target_length = 0.0;
  Vec2 begin_source, begin_target, end_source, end_target;
  bool pinned_first = false, pinned_last = false;
  double displacement_weight = 1.0;  // 1 / g^2
  double stretch_weight = kDefaultStretchWeight;
  double alpha = 1.0;
  const ArcCurve* target = nullptr;
  std::vector<double> vertex_arcs;      // arc position of each vertex of the target
  bool uneven_target = false;           // an edge longer than kUneven times the median
  const MatchRegion* region = nullptr;  // the hard constraint, where the region is a polygon
};

double orient(const Vec2& a, const Vec2& b, const Vec2& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

// p, on the line through a and b, lies within the segment a-b.
bool within(const Vec2& a, const Vec2& b, const Vec2& p) {
  return std::min(a.x(), b.x()) <= p.x() && p.x() <= std::max(a.x(), b.x()) && std::min(a.y(), b.y()) <= p.y() &&
         p.y() <= std::max(a.y(), b.y());
}

// The segments a0-a1 and b0-b1 meet other than at a shared end point: the definition of
// count_crossings (a start point lying on the neighbouring vector counts, as on pixel-grid frames
// where both run along one row).
bool cross(const Vec2& a0, const Vec2& a1, const Vec2& b0, const Vec2& b1) {
  const double d1 = orient(b0, b1, a0), d2 = orient(b0, b1, a1);
  const double d3 = orient(a0, a1, b0), d4 = orient(a0, a1, b1);
  if (((d1 < 0 && d2 > 0) || (d1 > 0 && d2 < 0)) && ((d3 < 0 && d4 > 0) || (d3 > 0 && d4 < 0))) return true;
  auto touches = [](double d, const Vec2& p, const Vec2& s0, const Vec2& s1) {
    return d == 0.0 && p != s0 && p != s1 && within(s0, s1, p);
  };
  return touches(d1, a0, b0, b1) || touches(d2, a1, b0, b1) || touches(d3, b0, a0, a1) || touches(d4, b1, a0, a1);
}

// One level: the starts `rows` (indices into Problem::starts, increasing), the target sampled at
// M + 1 positions, and for each row the range of samples it may take; with the region, which of
// those vectors lie inside it (row r, sample k at admitted[first[r] + k - lo[r]]).
struct Level {
  std::vector<Index> rows;
  Index samples = 0;         // M
  std::vector<double> arcs;  // arc position of each of the M + 1 samples along the target
  std::vector<Index> lo, hi;
  std::vector<char> admitted;
  std::vector<Index> first;
};

// The arc positions of the target samples of one level, strictly increasing, the ends exact
// (positions within 1e-9 of the target's length of a kept one dropped):
// - M + 1 equally spaced ones on a target with even edges;
// - on one with uneven edges (one longer than kUneven times the median), half of them equally
//   spaced and half at equal fractions of the way through the target's vertices: outlines are
//   traced densely where they have detail and sparsely along long edges (a flank closed by one
//   segment), equally spaced samples alone are coarser than the points there, and the stretch
//   term, which compares arc lengths between neighbours, then only sees multiples of the sample
//   step. Taking both rather than their mean maps fingers 5 and 6 long (tests/test_optimal.py);
//   M of them in all, as the DP's cost grows with the square of the samples;
// - the uniform map's position alpha * s of each of the level's starts, where the stretch term
//   is zero: a start a hair from a piece's end on a long target edge (the limb's flank, where the
//   curves cross on it) otherwise lands a whole sample step away; with them optimal's QM on the
//   limb outlines stays within 1.83 times normal mapping's (bench/README.md, "Real 2D outlines").
std::vector<double> sample_arcs(const Problem& p, Index samples, const std::vector<Index>& rows) {
  const Index even = p.uneven_target ? (samples + 1) / 2 : samples;
  std::vector<double> t(even + 1);
  for (Index k = 0; k <= even; ++k) t[k] = static_cast<double>(k) / static_cast<double>(even) * p.target_length;
  if (p.uneven_target) {
    const Index last_vertex = static_cast<Index>(p.vertex_arcs.size()) - 1;
    const Index through = samples - even;
    for (Index k = 1; k < through; ++k) {
      const double x = static_cast<double>(k) / static_cast<double>(through) * static_cast<double>(last_vertex);
      const Index j = std::min<Index>(static_cast<Index>(x), last_vertex - 1);
      const double f = x - static_cast<double>(j);
      t.push_back(p.vertex_arcs[j] + f * (p.vertex_arcs[j + 1] - p.vertex_arcs[j]));
    }
  }
  for (const Index r : rows) t.push_back(p.alpha * p.s[r]);
  std::sort(t.begin(), t.end());
  const double apart = 1e-9 * p.target_length;
  std::vector<double> kept{0.0};
  for (const double a : t) {
    if (a - kept.back() > apart && p.target_length - a > apart) kept.push_back(a);
  }
  kept.push_back(p.target_length);
  return kept;
}

// The index of the sample nearest to arc position a.
Index nearest_sample(const std::vector<double>& arcs, double a) {
  const auto above = std::lower_bound(arcs.begin(), arcs.end(), a);
  if (above == arcs.begin()) return 0;
  if (above == arcs.end()) return static_cast<Index>(arcs.size()) - 1;
  const Index k = static_cast<Index>(above - arcs.begin());
  return a - arcs[k - 1] <= arcs[k] - a ? k - 1 : k;
}

// The M + 1 target samples, the ends exactly the pieces' ends.
std::vector<Vec2> target_samples(const Problem& p, const Level& level) {
  std::vector<Vec2> q(level.samples + 1);
  for (Index k = 0; k <= level.samples; ++k) q[k] = p.target->point_at(level.arcs[k]);
  q[0] = p.begin_target, q[level.samples] = p.end_target;
  return q;
}

// Fills level.admitted from the region: one query per cell of the band. A pinned row's vector is
// a side of the region itself and always admitted.
void admit(const Problem& p, const std::vector<Index>& source_rows, Level& level) {
  const Index count = static_cast<Index>(level.rows.size());
  const std::vector<Vec2> q = target_samples(p, level);
  level.first.assign(count, 0);
  Index cells = 0;
  for (Index r = 0; r < count; ++r) level.first[r] = cells, cells += std::max<Index>(0, level.hi[r] - level.lo[r] + 1);
  std::vector<Index> rows(cells), segments(cells);
  Points2 ends(cells, 2);
  for (Index r = 0; r < count; ++r) {
    for (Index k = level.lo[r]; k <= level.hi[r]; ++k) {
      const Index c = level.first[r] + k - level.lo[r];
      rows[c] = source_rows[level.rows[r]];
      ends.row(c) = q[k].transpose();
      segments[c] = p.target->segment_at(level.arcs[k]);
    }
  }
  level.admitted = p.region->admits(rows, ends, segments);
  for (Index r = 0; r < count; ++r) {
    const bool pinned = (r == 0 && p.pinned_first) || (r == count - 1 && p.pinned_last);
    if (pinned && level.hi[r] >= level.lo[r]) level.admitted[level.first[r]] = 1;
  }
}

// Feasible sample range of row r of R so that a strictly increasing path exists.
std::pair<Index, Index> feasible(const Problem& p, Index r, Index count, Index samples) {
  if (r == 0 && p.pinned_first) return {0, 0};
  if (r == count - 1 && p.pinned_last) return {samples, samples};
  const Index lo = p.pinned_first ? r : r + 1;
  const Index hi = p.pinned_last ? samples - (count - 1 - r) : samples - (count - r);
  return {lo, hi};
}

Index max_step(Index samples, Index count) { return 8 * samples / (count + 1) + 2; }

// The DP on one level: fills path (a sample per row) and energy; false if the ranges admit no
// path.
bool solve_level(const Problem& p, const Level& level, std::vector<Index>& path, double& energy) {
  const Index count = static_cast<Index>(level.rows.size());
  const Index samples = level.samples;
  const std::vector<double>& t = level.arcs;
  const Index reach = max_step(samples, count);
  const std::vector<Vec2> q = target_samples(p, level);
  // With the region every vector taken lies inside it, so none can cross another (optimal.hpp):
  // the crossing penalty is not needed.
  const bool constrained = !level.admitted.empty();

  auto stretch = [&](double target_gap, double source_gap) {
    if (!(source_gap > 0.0)) return 0.0;
    const double r = target_gap / (p.alpha * source_gap) - 1.0;
    return p.stretch_weight * r * r;
  };

  std::vector<std::vector<double>> cost(count);
  std::vector<std::vector<std::int32_t>> back(count);
  // Whether the vector p -> end crosses one of the kRecent vectors before it on the best path
  // into (r - 1, kp): its neighbour exactly, the ones further back as that path has them (the
  // DP's state holds one vector; staircase contours cross two or three apart).
  auto crosses_recent = [&](const Level& lv, const std::vector<std::vector<std::int32_t>>& from_row, Index r, Index kp,
                            const Vec2& point, const Vec2& end) {
    Index k_back = kp;
    for (Index d = 1; d <= kRecent && r - d >= 0; ++d) {
      if (d > 1) {
        k_back = from_row[r - d + 1][k_back - lv.lo[r - d + 1]];
        if (k_back < 0) break;
      }
      if (cross(p.starts.row(lv.rows[r - d]).transpose(), q[k_back], point, end)) return true;
    }
    return false;
  };
  for (Index r = 0; r < count; ++r) {
    if ((r & 63) == 0) detail::check_interrupt();
    const Index lo = level.lo[r], hi = level.hi[r];
    if (lo > hi) return false;
    const Index i = level.rows[r];
    const Vec2 pi = p.starts.row(i).transpose();
    cost[r].assign(hi - lo + 1, kInf);
    back[r].assign(hi - lo + 1, -1);
    // The previous vector: the virtual one at the start of the pieces, or row r - 1.
    const bool first = r == 0;
    const double prev_s = first ? 0.0 : p.s[level.rows[r - 1]];
    const Index plo = first ? 0 : level.lo[r - 1], phi = first ? 0 : level.hi[r - 1];
    const double dl = p.s[i] - prev_s;
    // A long source edge (curves are not resampled by default) may take as long a target arc.
    const Index row_reach =
        p.source_length > 0.0
            ? std::max(reach,
                       static_cast<Index>(std::ceil(8.0 * static_cast<double>(samples) * dl / p.source_length)) + 2)
            : reach;
    for (Index k = lo; k <= hi; ++k) {
      if (constrained && !level.admitted[level.first[r] + k - lo]) continue;
      const double displacement = p.displacement_weight * (pi - q[k]).squaredNorm();
      double best = kInf;
      Index arg = -1;
      const bool pinned = first && p.pinned_first;
      const Index from = std::max(plo, pinned ? k : k - row_reach), to = std::min(phi, pinned ? k : k - 1);
      for (Index kp = from; kp <= to; ++kp) {
        const double before = first ? 0.0 : cost[r - 1][kp - plo];
        if (before == kInf) continue;
        double c = before + stretch(t[k] - t[kp], dl);
        if (!(c < best)) continue;  // the crossing tests only where the step could win
        if (!first && !constrained && crosses_recent(level, back, r, kp, pi, q[k])) c += kCrossing;
        if (c < best) best = c, arg = kp;
      }
      if (arg >= 0) cost[r][k - lo] = best + displacement, back[r][k - lo] = static_cast<std::int32_t>(arg);
    }
  }
  // Close onto the virtual vector at the end of the pieces.
  const Index last = level.rows[count - 1];
  const double dl = p.source_length - p.s[last];
  double best = kInf;
  Index arg = -1;
  for (Index k = level.lo[count - 1]; k <= level.hi[count - 1]; ++k) {
    double c = cost[count - 1][k - level.lo[count - 1]];
    if (c == kInf) continue;
    if (!(p.pinned_last)) {
      c += stretch(p.target_length - t[k], dl);
      if (!constrained && cross(p.starts.row(last).transpose(), q[k], p.end_source, p.end_target)) c += kCrossing;
    }
    if (c < best) best = c, arg = k;
  }
  if (arg < 0) return false;
  energy = best;
  path.assign(count, 0);
  for (Index r = count - 1; r >= 0; --r) {
    path[r] = arg;
    arg = back[r][arg - level.lo[r]];
  }
  return true;
}

// The coarser path carried to a finer level: the target position of each fine row, linear in
// the source position between the coarse rows (and the virtual ends).
std::vector<double> carry(const Problem& p, const std::vector<Index>& coarse_rows, const std::vector<double>& coarse_t,
                          const std::vector<Index>& fine_rows) {
  std::vector<double> s{0.0}, t{0.0};
  for (std::size_t c = 0; c < coarse_rows.size(); ++c) s.push_back(p.s[coarse_rows[c]]), t.push_back(coarse_t[c]);
  s.push_back(p.source_length), t.push_back(p.target_length);
  std::vector<double> out(fine_rows.size());
  std::size_t j = 0;
  for (std::size_t r = 0; r < fine_rows.size(); ++r) {
    const double x = p.s[fine_rows[r]];
    while (j + 2 < s.size() && s[j + 1] <= x) ++j;
    const double span = s[j + 1] - s[j];
    const double f = span > 0.0 ? std::clamp((x - s[j]) / span, 0.0, 1.0) : 0.0;
    out[r] = t[j] + f * (t[j + 1] - t[j]);
  }
  return out;
}

// All levels, coarse to fine, into the target positions of the starts (coarse_t) and the energy.
// With p.region the finest level takes only vectors inside the region, its band widened at most
// kWidenings times (false when that finds no path); a coarser level that finds none there is
// solved without it (it only centres the next band). Without the region a band is widened until
// a path exists.
bool solve_levels(const Problem& p, const std::vector<std::vector<Index>>& levels, Index finest,
                  const std::vector<Index>& start_rows, std::vector<double>& coarse_t, double& energy) {
  const Index n = static_cast<Index>(levels.front().size());
  std::vector<Index> coarse_rows;
  for (auto level_rows = levels.rbegin(); level_rows != levels.rend(); ++level_rows) {
    Level level;
    level.rows = *level_rows;
    const bool finest_level = level_rows + 1 == levels.rend();
    const Index count = static_cast<Index>(level.rows.size());
    level.samples = std::max(4 * (count + 1), (finest * (count + 1) + n) / (n + 1));
    level.arcs = sample_arcs(p, level.samples, level.rows);
    level.samples = static_cast<Index>(level.arcs.size()) - 1;
    const std::vector<double> centre =
        coarse_rows.empty() ? std::vector<double>() : carry(p, coarse_rows, coarse_t, level.rows);
    const Index first_band = std::max<Index>(16, 8 * level.samples / (count + 1));
    Index band = first_band;
    bool constrained = p.region != nullptr;
    std::vector<Index> path;
    for (;;) {
      level.lo.resize(count), level.hi.resize(count);
      for (Index r = 0; r < count; ++r) {
        auto [lo, hi] = feasible(p, r, count, level.samples);
        if (!centre.empty() && band < level.samples) {
          const Index c = nearest_sample(level.arcs, centre[r]);
          lo = std::max(lo, c - band), hi = std::min(hi, c + band);
        }
        level.lo[r] = lo, level.hi[r] = hi;
      }
      if (constrained) {
        admit(p, start_rows, level);
      } else {
        level.admitted.clear();
      }
      if (solve_level(p, level, path, energy)) break;
      if (constrained && !centre.empty() && band < (first_band << kWidenings) && band < level.samples) {
        band *= 2;
        continue;
      }
      if (constrained) {
        if (finest_level) return false;
        constrained = false, band = first_band;
        continue;
      }
      if (centre.empty() || band >= level.samples) {
        throw GeometryError("optimal: no monotone matching (more start points than the target can separate)");
      }
      band *= 2;
    }
    coarse_rows = level.rows;
    coarse_t.resize(count);
    for (Index r = 0; r < count; ++r) coarse_t[r] = level.arcs[path[r]];
  }
  return true;
}

// Where the source doubles back next to a piece's end (a traced tip whose last point lies back
// across the one before it), every strictly increasing path crosses that end's vector: a
// crossing-free order-preserving field exists only with the rows between sharing its end point.
// For each crossing pair of rows a < b of which one is fixed (a pinned row, or an end vector as
// row -1 or n; `starts` holds the starts and then the end vectors, in virtual_rows' order), the
// free rows from the other one up to it take its end, if that leaves fewer crossings; the ends
// then increase along the target but not strictly there. Crossings among free rows are left (a
// field that collapsed them would not be the bijective matching optimal.hpp promises). Returns
// the crossings left.
Index merge_crossing_ends(const Problem& p, const Points2& starts, const std::vector<Index>& virtual_rows,
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

  Problem p;
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
  // The path's ends and an exact count of its crossings.
  std::vector<double> coarse_t;
  double energy = 0.0;
  auto take = [&] {
    for (Index r = 0; r < n; ++r) {
      match.arcs[r] = coarse_t[r];
      match.points.row(r) = curve.point_at(coarse_t[r]).transpose();
    }
    if (p.pinned_first) match.points.row(0) = p.begin_target.transpose();
    if (p.pinned_last) match.points.row(n - 1) = p.end_target.transpose();
    match.energy = energy;
    Points2 ends(starts.rows(), 2);
    ends.topRows(n) = match.points;
    for (std::size_t e = 0; e < to.size(); ++e) ends.row(n + static_cast<Index>(e)) = to[e].transpose();
    return count_crossings(starts, ends);
  };

  // With the region: crossing-free by construction where it is a simple polygon (or the cut ring);
  // where it is not, its vectors are still the likeliest to be free of crossings. Without a path
  // inside it, the penalised one. Every result is counted exactly (the line queries round at 1e-9
  // of a vector's length) and returned only without crossings.
  const bool free_rows = n > static_cast<Index>(p.pinned_first) + static_cast<Index>(p.pinned_last);
  std::unique_ptr<MatchRegion> region;
  std::string why_not;
  Index crossings = 0;
  bool inside = false;
  if (free_rows) {
    region = std::make_unique<MatchRegion>(source, target);
    why_not = region->why_not();
    p.region = region.get();
    inside = solve_levels(p, levels, finest, start_rows, coarse_t, energy);
    if (inside) crossings = take();
  } else {
    solve_levels(p, levels, finest, start_rows, coarse_t, energy);
    crossings = take();
  }
  match.by_construction = inside && why_not.empty() && crossings == 0;
  if (free_rows && (!inside || crossings > 0)) {
    if (why_not.empty()) {
      why_not = inside ? "the vectors inside the region cross by rounding"
                       : "no path of vectors inside the region between them was found at the matching's sampling";
    }
    p.region = nullptr;
    solve_levels(p, levels, finest, start_rows, coarse_t, energy);
    crossings = take();
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
