// Method "optimal"'s dynamic programming: start points x target samples, one level at a time, the
// coarsest on the full grid and each finer one in a band around the coarser path.
#include "mapping/optimal_levels.hpp"

#include <morphomap/errors.hpp>

#include "common/interrupt_check.hpp"
#include "common/numbers.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace morphomap::detail {

namespace {

constexpr double kCrossing = 1e6;  // without the region: added where two close vectors cross
constexpr Index kRecent = 3;       // vectors back along the path checked for crossings
constexpr Index kWidenings = 4;    // with the region: doublings of a level's band before giving up

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

// One level: the starts `rows` (indices into MatchProblem::starts, increasing), the target sampled at
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
std::vector<double> sample_arcs(const MatchProblem& p, Index samples, const std::vector<Index>& rows) {
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
std::vector<Vec2> target_samples(const MatchProblem& p, const Level& level) {
  std::vector<Vec2> q(level.samples + 1);
  for (Index k = 0; k <= level.samples; ++k) q[k] = p.target->point_at(level.arcs[k]);
  q[0] = p.begin_target, q[level.samples] = p.end_target;
  return q;
}

// Fills level.admitted from the region: one query per cell of the band, but for the cells the
// same level's narrower band (`before`, where a band is widened) answered already. A pinned row's
// vector is a side of the region itself and always admitted.
void admit(const MatchProblem& p, const std::vector<Index>& source_rows, Level& level, const Level* before) {
  const Index count = static_cast<Index>(level.rows.size());
  const std::vector<Vec2> q = target_samples(p, level);
  level.first.assign(count, 0);
  Index cells = 0;
  for (Index r = 0; r < count; ++r) level.first[r] = cells, cells += std::max<Index>(0, level.hi[r] - level.lo[r] + 1);
  level.admitted.assign(cells, 0);
  std::vector<std::pair<Index, Index>> asked;  // (row, sample) of each cell to query
  asked.reserve(cells);
  for (Index r = 0; r < count; ++r) {
    for (Index k = level.lo[r]; k <= level.hi[r]; ++k) {
      if (before != nullptr && before->lo[r] <= k && k <= before->hi[r]) {
        level.admitted[level.first[r] + k - level.lo[r]] = before->admitted[before->first[r] + k - before->lo[r]];
      } else {
        asked.emplace_back(r, k);
      }
    }
  }
  const Index m = static_cast<Index>(asked.size());
  std::vector<Index> rows(m), segments(m);
  Points2 ends(m, 2);
  for (Index a = 0; a < m; ++a) {
    const auto [r, k] = asked[a];
    rows[a] = source_rows[level.rows[r]];
    ends.row(a) = q[k].transpose();
    segments[a] = p.target->segment_at(level.arcs[k]);
  }
  const std::vector<char> answers = p.region->admits(rows, ends, segments);
  for (Index a = 0; a < m; ++a)
    level.admitted[level.first[asked[a].first] + asked[a].second - level.lo[asked[a].first]] = answers[a];
  for (Index r = 0; r < count; ++r) {
    const bool pinned = (r == 0 && p.pinned_first) || (r == count - 1 && p.pinned_last);
    if (pinned && level.hi[r] >= level.lo[r]) level.admitted[level.first[r]] = 1;
  }
}

// Feasible sample range of row r of R so that a strictly increasing path exists.
std::pair<Index, Index> feasible(const MatchProblem& p, Index r, Index count, Index samples) {
  if (r == 0 && p.pinned_first) return {0, 0};
  if (r == count - 1 && p.pinned_last) return {samples, samples};
  const Index lo = p.pinned_first ? r : r + 1;
  const Index hi = p.pinned_last ? samples - (count - 1 - r) : samples - (count - r);
  return {lo, hi};
}

Index max_step(Index samples, Index count) { return 8 * samples / (count + 1) + 2; }

// The DP on one level: fills path (a sample per row) and energy; false if the ranges admit no
// path. `jumped` is set where the path was found only through a forced jump.
bool solve_level(const MatchProblem& p, const Level& level, std::vector<Index>& path, double& energy, bool& jumped) {
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
    if ((r & 63) == 0) check_interrupt();
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
    // One pass over the row's cells; with `forced`, each cell out of reach of every vector of the
    // row before takes its step from the furthest of them instead.
    auto relax = [&](bool forced, Index last_finite) {
      bool any = false;
      for (Index k = lo; k <= hi; ++k) {
        if (constrained && !level.admitted[level.first[r] + k - lo]) continue;
        const bool pinned = first && p.pinned_first;
        Index from = std::max(plo, pinned ? k : k - row_reach);
        const Index to = std::min(phi, pinned ? k : k - 1);
        if (forced) {
          if (from <= last_finite) continue;  // reached in the first pass
          from = std::max(plo, last_finite - reach);
        }
        const double displacement = p.displacement_weight * (pi - q[k]).squaredNorm();
        double best = kInf;
        Index arg = -1;
        for (Index kp = from; kp <= to; ++kp) {
          const double before = first ? 0.0 : cost[r - 1][kp - plo];
          if (before == kInf) continue;
          double c = before + stretch(t[k] - t[kp], dl);
          if (!(c < best)) continue;  // the crossing tests only where the step could win
          if (!first && !constrained && crosses_recent(level, back, r, kp, pi, q[k])) c += kCrossing;
          if (c < best) best = c, arg = kp;
        }
        if (arg >= 0) {
          cost[r][k - lo] = best + displacement, back[r][k - lo] = static_cast<std::int32_t>(arg);
          any = true;
        }
      }
      return any;
    };
    // With the region, every vector inside it may be out of reach of every vector the row before
    // can take: where the source turns a corner, the part of the target its starts see jumps ahead
    // (limb 330->381 h resampled to 10^3-10^4 points: 85 samples in one step, against a reach of
    // 41). There the jump is forced, and taken from the furthest vectors of the row before.
    if (!relax(false, -1) && constrained && !first) {
      Index last_finite = -1;
      for (Index kp = phi; kp >= plo && last_finite < 0; --kp) {
        if (cost[r - 1][kp - plo] < kInf) last_finite = kp;
      }
      if (last_finite >= 0 && relax(true, last_finite)) jumped = true;
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

// The coarser path carried to a finer level: for each fine row, the target positions of the
// coarse rows before and after it (the virtual ends beyond the first and last). A monotone fine
// path runs between them wherever it follows the coarse one, so the band spans that bracket rather
// than a point interpolated in it: where a short stretch of the source fans out over a long arc
// of the target (a bud's tip), the fine rows inside the region take the fan's arc all at one
// corner, not evenly along it.
std::vector<std::pair<double, double>> carry(const MatchProblem& p, const std::vector<Index>& coarse_rows,
                                             const std::vector<double>& coarse_t, const std::vector<Index>& fine_rows) {
  std::vector<std::pair<double, double>> out(fine_rows.size());
  std::size_t c = 0;  // the first coarse row at or after the fine row
  for (std::size_t r = 0; r < fine_rows.size(); ++r) {
    while (c < coarse_rows.size() && coarse_rows[c] < fine_rows[r]) ++c;
    const double before = c > 0 ? coarse_t[c - 1] : 0.0;
    const std::size_t after = c < coarse_rows.size() && coarse_rows[c] == fine_rows[r] ? c + 1 : c;
    out[r] = {before, after < coarse_rows.size() ? coarse_t[after] : p.target_length};
  }
  return out;
}

}  // namespace

bool solve_levels(const MatchProblem& p, const std::vector<std::vector<Index>>& levels, Index finest,
                  const std::vector<Index>& start_rows, std::vector<double>& coarse_t, double& energy, bool& jumped) {
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
    const std::vector<std::pair<double, double>> bracket =
        coarse_rows.empty() ? std::vector<std::pair<double, double>>() : carry(p, coarse_rows, coarse_t, level.rows);
    // Beyond the bracket, a margin of some starts' worth of samples, doubled where no path is found.
    const Index margin = n <= kSmallMatch ? 8 : 2;
    const Index first_band = std::max<Index>(8, margin * level.samples / (count + 1));
    Index band = first_band;
    bool constrained = p.region != nullptr;
    std::vector<Index> path;
    Level before;  // the last constrained attempt at this level, whose answers a wider band reuses
    for (;;) {
      if (constrained && !level.admitted.empty()) before = level;
      level.lo.resize(count), level.hi.resize(count);
      for (Index r = 0; r < count; ++r) {
        auto [lo, hi] = feasible(p, r, count, level.samples);
        if (!bracket.empty() && band < level.samples) {
          lo = std::max(lo, nearest_sample(level.arcs, bracket[r].first) - band);
          hi = std::min(hi, nearest_sample(level.arcs, bracket[r].second) + band);
        }
        level.lo[r] = lo, level.hi[r] = hi;
      }
      if (constrained) {
        admit(p, start_rows, level, before.admitted.empty() ? nullptr : &before);
      } else {
        level.admitted.clear();
      }
      if (solve_level(p, level, path, energy, jumped)) break;
      if (constrained && !bracket.empty() && band < (first_band << kWidenings) && band < level.samples) {
        band *= 2;
        continue;
      }
      if (constrained) {
        if (finest_level) return false;
        constrained = false, band = first_band;
        continue;
      }
      if (bracket.empty() || band >= level.samples) {
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

}  // namespace morphomap::detail
