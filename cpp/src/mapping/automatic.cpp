// The default ("auto") and the paper's Algorithm 1 ("paper") on one job of map_curves.
#include <morphomap/crossings.hpp>
#include <morphomap/errors.hpp>
#include <morphomap/quality.hpp>
#include <morphomap/transform.hpp>

#include "common/run_both.hpp"
#include "common/validation.hpp"
#include "curves/arc_curve.hpp"
#include "curves/crossing_sweep.hpp"
#include "curves/unchecked.hpp"
#include "mapping/curve_job.hpp"
#include "quality/checked_quality.hpp"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace morphomap::detail {

namespace {

using Unchecked = CurveIndexUnchecked;

// Start points per gap: the mean distance from the starts to the target over their mean spacing
// along the source.
double point_density(const Job& job, const Points2& starts) {
  const double gap = Unchecked::closest_points(target_index(job), starts).distances.mean();
  const double spacing = ArcCurve::unchecked(job.source, job.source_closed).length() / starts.rows();
  return spacing > 0.0 ? gap / spacing : 0.0;
}

}  // namespace

// "paper": the paper's Algorithm 1 on one job: normal mapping, and reverse diffusion instead when
// normal mapping gives crossings or misses (with a density threshold, the first attempt is reverse
// minimal distance where the start points are denser than the threshold: the paper's "limiting
// case of an infinite number of points"). Where reverse diffusion fails on a piece (its mesh
// cannot be made, streamlines stall), it still answers:
// forward diffusion, which is crossing-free too; then the first attempt if it missed nothing
// (crossings and all); then minimal distance, which always finds a point.
Vectors paper_algorithm(const Job& job, const std::vector<double>& start_keys, const ArcCurve& whole_source,
                        const CurveIndex& whole_source_index, const Settings& settings) {
  if (job.start_rows.empty()) return forward(MapMethod::normal, job, start_keys, settings);
  const Vectors first =
      settings.density_threshold > 0.0 && point_density(job, start_points(job)) > settings.density_threshold
          ? reverse(MapMethod::minimal_distance, job, whole_source, whole_source_index, settings)
          : forward(MapMethod::normal, job, start_keys, settings);
  if (complete(first) && !any_crossing(first.starts, first.ends)) return first;
  for (const bool backwards : {true, false}) {
    try {
      Vectors v = backwards ? reverse(MapMethod::diffusion, job, whole_source, whole_source_index, settings)
                            : forward(MapMethod::diffusion, job, start_keys, settings);
      // (A reverse mapping from a target piece without points of its own between the two
      // meetings has no vectors at all: that leaves the piece of C1 unmapped, not complete.)
      if (complete(v) && v.starts.rows() > 0) return v;
    } catch (const GeometryError&) {
    } catch (const InvalidInput&) {  // a piece the region of which is not what diffusion needs
    }
  }
  if (complete(first)) return first;
  return forward(MapMethod::minimal_distance, job, start_keys, settings);
}

namespace {

// The default's threshold for trying the diffusion candidates: a cheap candidate with a QM at most
// this is kept (the real pairs' best fields have QM 1e-4 to 0.4; bench/README.md, "Real 2D
// outlines"); above it the tenth of a second diffusion costs is worth spending.
constexpr double kGoodEnough = 1.0;
// ... judged on the field thinned to at most this many vectors, the density of the outlines that
// set kGoodEnough: where one step of the source fans out over an arc of the target, that step's
// share of QM1 and QM2 grows with the square of the points per curve, so the same fan measures
// QM 0.28 at 200 points and 4.3 at 10^4 (optimal on limb 330->381 h open, bench/README.md "Real 2D
// outlines"). Unthinned, the diffusion candidates (seconds each at 10^4 points) would run for a
// field as good as one kept at 200.
constexpr Index kJudged = 200;

// One candidate of the default on one job, measured on the job's piece as best.py measures a piece:
// its vectors with the meetings' own at the piece's ends.
struct Scored {
  Vectors vectors;
  Index misses = 0;
  double qm = std::numeric_limits<double>::infinity();  // NaN measures rank last
  double judged = qm;                                   // QM thinned to kJudged vectors
  std::string failure;                                  // why it is not admissible ("" when it is)
};

Scored measured(const Job& job, Vectors v) {
  Scored s;
  const Index m = v.starts.rows();
  const Index b = job.shared_begin ? 1 : 0, e = job.shared_end ? 1 : 0;
  DisplacementField2 f;
  f.starts.resize(m + b + e, 2);
  f.ends.resize(m + b + e, 2);
  if (b) f.starts.row(0) = job.source.row(0), f.ends.row(0) = job.target.row(0);
  f.starts.middleRows(b, m) = v.starts, f.ends.middleRows(b, m) = v.ends;
  if (e) {
    f.starts.row(m + b) = job.source.row(job.source.rows() - 1);
    f.ends.row(m + b) = job.target.row(job.target.rows() - 1);
  }
  for (Index i = 0; i < m; ++i) s.misses += v.ends.row(i).allFinite() ? 0 : 1;
  if (s.misses > 0) s.failure = std::to_string(s.misses) + " misses";
  if (any_crossing(f.starts, f.ends)) s.failure += (s.failure.empty() ? "" : ", ") + std::string("crossings");
  auto qm_of = [&](const DisplacementField2& field) {
    try {
      const double qm =
          checked_quality(field, job.source, source_index(job), job.target, target_index(job), job.source_closed, false)
              .qm;
      if (std::isfinite(qm)) return qm;
    } catch (const InvalidInput&) {  // a piece too degenerate to measure (a target shrunk to a point)
    }
    return std::numeric_limits<double>::infinity();
  };
  if (s.failure.empty()) {
    s.qm = s.judged = qm_of(f);
    if (m > kJudged) {
      const Index stride = (m + kJudged - 1) / kJudged;
      std::vector<Index> rows;
      if (b) rows.push_back(0);
      for (Index i = 0; i < m; i += stride) rows.push_back(b + i);
      if (e) rows.push_back(m + b);
      DisplacementField2 thinned;
      thinned.starts = f.starts(rows, Eigen::all), thinned.ends = f.ends(rows, Eigen::all);
      s.judged = qm_of(thinned);
    }
  }
  s.vectors = std::move(v);
  return s;
}

// A reverse field (from the target's points) carried onto the job's own start points: each start
// point's end lies the same fraction of the way along the target between the ends of the two
// reverse vectors whose starts bracket it on the source. On an open piece its ends bracket the
// first and the last start; on whole closed curves the brackets wrap round, and the target is
// walked the way it turns relative to the source. None where the reverse field does not keep the
// order (its ends, taken in the order of its starts along the source, step back along the target).
std::optional<Vectors> carried(const Vectors& back, const Job& job, const std::vector<double>& start_keys,
                               Method label) {
  if (!complete(back) || back.starts.rows() == 0) return std::nullopt;
  const bool closed = job.source_closed;
  const ArcCurve source = ArcCurve::unchecked(job.source, closed);
  const ArcCurve target = ArcCurve::unchecked(job.target, closed);
  const double ls = source.length(), lt = target.length();
  const Vector a = Unchecked::closest_points(Unchecked::build(job.source, closed), back.starts).arc_lengths;
  const Vector b = Unchecked::closest_points(target_index(job), back.ends).arc_lengths;
  // Knots (arc along the source, arc along the target unrolled from the first knot's end).
  std::vector<std::pair<double, double>> knots;
  const int way = closed ? relative_direction(source, target) : 1;
  if (!closed) knots.emplace_back(0.0, 0.0);
  for (Index j = 0; j < a.size(); ++j) knots.emplace_back(a[j], b[j]);
  if (!closed) knots.emplace_back(ls, lt);
  std::sort(knots.begin(), knots.end());
  double origin = 0.0;
  if (closed) {
    origin = knots.front().second;
    for (auto& k : knots) k.second = std::fmod(way * (k.second - origin) + 2.0 * lt, lt);
    // Once round: the first knot again at the end, a whole turn of both curves on.
    knots.emplace_back(knots.front().first + ls, knots.front().second + lt);
    knots.insert(knots.begin(), {knots[knots.size() - 2].first - ls, knots[knots.size() - 2].second - lt});
  }
  for (std::size_t k = 1; k < knots.size(); ++k) {
    if (knots[k].second < knots[k - 1].second) return std::nullopt;
  }
  Vectors v;
  v.starts = start_points(job);
  v.keys = start_keys;
  v.ends.resize(v.starts.rows(), 2);
  v.methods.assign(v.starts.rows(), label);
  for (std::size_t j = 0; j < job.start_rows.size(); ++j) {
    const double s = source.arc(job.start_rows[j]);
    auto above = std::upper_bound(knots.begin(), knots.end(), std::make_pair(s, std::numeric_limits<double>::max()));
    if (above == knots.end()) above = std::prev(above);
    if (above == knots.begin()) above = std::next(above);
    const auto below = std::prev(above);
    const double span = above->first - below->first;
    const double f = span > 0.0 ? std::clamp((s - below->first) / span, 0.0, 1.0) : 0.0;
    const double along = below->second + f * (above->second - below->second);
    v.ends.row(j) = target.point_at(closed ? target.wrap(origin + way * along) : along).transpose();
  }
  return v;
}

// The start points of a job, for messages: how many and between which points.
std::string job_place(const Job& job) {
  const Points2 starts = start_points(job);
  auto at = [](const Points2& p, Index i) {
    return "(" + std::to_string(p(i, 0)) + ", " + std::to_string(p(i, 1)) + ")";
  };
  return std::to_string(starts.rows()) + " start points of c1 from " + at(starts, 0) + " to " +
         at(starts, starts.rows() - 1);
}

}  // namespace

// The default, on each job: the crossing-free, complete candidate of lowest QM. First the ones
// that cost milliseconds: normal mapping, the order-preserving optimal matching, minimal distance,
// and reverse minimal distance and reverse optimal carried onto the start points (a coarse C1
// matched from a fine C2 is matched from its own few points). Where none of them qualifies with
// QM <= kGoodEnough, also the ones that solve a diffusion problem (tenths of a second): diffusion
// and reverse diffusion carried onto the start points. Where none qualifies, GeometryError. Every
// candidate maps the job's own start points, so the field has one vector per start point of C1,
// in its order. Why not the paper's Algorithm 1: its reverse diffusion maps from C2's points, and
// its straight vectors cross where the streamlines fan into a lobe (bench/README.md, "Real 2D
// outlines").
Vectors default_choice(const Job& job, const std::vector<double>& start_keys, const ArcCurve& whole_source,
                       const CurveIndex& whole_source_index, const Settings& settings) {
  if (job.start_rows.empty()) return forward(MapMethod::normal, job, start_keys, settings);
  std::string why;
  auto note = [&](const std::string& name, const std::string& what) {
    why += (why.empty() ? "" : "; ") + name + ": " + what;
  };
  // One candidate: (name, the vectors or none); a failure is noted and ranks nowhere.
  auto attempt = [&](const std::string& name, auto make) -> Scored {
    Scored failed;
    failed.failure = "failed";
    try {
      std::optional<Vectors> v = make();
      if (!v) {
        note(name, "does not keep the order");
        return failed;
      }
      Scored s = measured(job, std::move(*v));
      if (!s.failure.empty()) note(name, s.failure);
      return s;
    } catch (const GeometryError& error) {
      note(name, error.what());
    } catch (const InvalidInput& error) {  // a piece whose region is not what diffusion needs
      note(name, error.what());
    }
    return failed;
  };
  auto plain = [&](MapMethod method) {
    return [&, method]() -> std::optional<Vectors> { return forward(method, job, start_keys, settings); };
  };
  auto backwards = [&](MapMethod method) {
    return [&, method]() -> std::optional<Vectors> {
      return carried(reverse(method, job, whole_source, whole_source_index, settings), job, start_keys,
                     reversed(basic_method(method)));
    };
  };
  Scored best;
  best.failure = "none";
  auto consider = [&](Scored s) {
    if (s.failure.empty() && (!best.failure.empty() || s.qm < best.qm)) best = std::move(s);
  };
  consider(attempt("normal", plain(MapMethod::normal)));
  consider(attempt("optimal", plain(MapMethod::optimal)));
  consider(attempt("minimal_distance", plain(MapMethod::minimal_distance)));
  consider(attempt("reverse_minimal_distance", backwards(MapMethod::minimal_distance)));
  consider(attempt("reverse_optimal", backwards(MapMethod::optimal)));
  if (!best.failure.empty() || !(best.judged <= kGoodEnough)) {
    consider(attempt("diffusion", plain(MapMethod::diffusion)));
    consider(attempt("reverse_diffusion", backwards(MapMethod::diffusion)));
  }
  if (!best.failure.empty()) {
    throw GeometryError("map_curves: no crossing-free complete field for " + job_place(job) + " (" + why +
                        "); try method='best', or map the other way round (reverse=True)");
  }
  return std::move(best.vectors);
}

namespace {

// Appendix A's alignment without its greedy search (a tolerance above its first step): open curves
// ends onto ends; closed ones scaled to C2's area about C1's centroid, and moved centroid onto
// centroid where that overlaps more. The search would cost ten times the mapping
// (bench/README.md, "Real 2D outlines").
constexpr double kNoSearch = 1.0;

// Start points carried back from a moved C1 by the inverse similarity lie on C1's points within
// rounding, not bit for bit: the ones that do (in order along C1) are put exactly on them. The
// others are split points where the moved C1 met C2, not points of C1: their rows are dropped.
void keep_points_of(DisplacementField2& field, const Points2Ref& curve, double tolerance) {
  constexpr Index kLookahead = 3;  // rows of C1 without a start of their own (at a split point)
  std::vector<Index> kept;
  Index next = 0;
  for (Index r = 0; r < field.starts.rows() && next < curve.rows(); ++r) {
    for (Index i = next; i < std::min(curve.rows(), next + kLookahead); ++i) {
      if ((field.starts.row(r) - curve.row(i)).norm() <= tolerance) {
        field.starts.row(r) = curve.row(i);
        kept.push_back(r);
        next = i + 1;
        break;
      }
    }
  }
  if (static_cast<Index>(kept.size()) == field.starts.rows()) return;
  field.starts = Points2(field.starts(kept, Eigen::all));
  field.ends = Points2(field.ends(kept, Eigen::all));
  std::vector<Method> methods;
  for (const Index r : kept) methods.push_back(field.methods[r]);
  field.methods = std::move(methods);
}

// QM of a field the caller found crossing-free, on C1 and C2 with their indexes.
double field_qm(const DisplacementField2& field, const Points2Ref& c1, const CurveIndex& index1, const Points2Ref& c2,
                const CurveIndex& index2, bool closed) {
  try {
    const double qm = checked_quality(field, c1, index1, c2, index2, closed, false).qm;
    return std::isfinite(qm) ? qm : std::numeric_limits<double>::infinity();
  } catch (const InvalidInput&) {
    return std::numeric_limits<double>::infinity();
  }
}

}  // namespace

// "auto" without transform, n or reverse: the default's field of the pair as given, and of the
// pair with C1 moved near C2 by a similarity (carried back onto C1, so again one vector per point of C1); the
// moved one counts only where it is complete and crossing-free on the curves as given; the lower
// QM wins. Consecutive frames differ by growth more than by shape: mapped from a C1 of C2's size,
// the vectors spread evenly (bench/README.md, "Real 2D outlines").
DisplacementField2 mapped_choice(const Points2Ref& c1, Index n1, const CurveIndex* index1, const Points2Ref& c2,
                                 Index n2, const CurveIndex* index2, const CurveMappingOptions& options) {
  if (options.method != MapMethod::automatic) return mapped_pair(c1, n1, index1, c2, n2, index2, options);
  if (options.transform) {
    // Crossing-free on the moved C1 need not be on C1 as given: said, never returned.
    DisplacementField2 field = mapped_pair(c1, n1, index1, c2, n2, index2, options);
    const auto pairs = crossing_pairs(field.starts, field.ends);
    if (!pairs.empty()) {
      throw GeometryError("map_curves: the field mapped from C1 moved by Appendix A's transform has " +
                          std::to_string(pairs.size()) +
                          " crossing pairs once its start points are carried back onto C1; map without "
                          "transform=True (the default tries a moved C1 itself and keeps it only without "
                          "crossings)");
    }
    return field;
  }
  // The moved field's start points are C1's own rows only when C1's points are the start points
  // (not resampled, not found from C2). The two passes are independent: both cores at once (the
  // kidney at 10^4 points per curve, bench/README.md, "Real 2D outlines").
  const bool try_moved = !(options.reverse || options.n > 0);
  std::optional<DisplacementField2> plain, moved;
  std::string why;
  auto run_plain = [&] {
    try {
      plain = mapped_pair(c1, n1, index1, c2, n2, index2, options);
    } catch (const GeometryError& error) {
      why = error.what();
    }
  };
  auto run_moved = [&] {
    if (!try_moved) return;
    try {
      const Points2 p1 = c1.topRows(n1), p2 = c2.topRows(n2);
      const Similarity2 similarity = align_curves(p1, p2, options.closed, kNoSearch);
      DisplacementField2 field = mapped_pair(c1, n1, index1, c2, n2, index2, options, &similarity);
      const double size = (p1.colwise().maxCoeff() - p1.colwise().minCoeff()).norm();
      keep_points_of(field, p1, 1e-9 * size);
      if (field.starts.allFinite() && field.ends.allFinite() && !any_crossing(field.starts, field.ends)) {
        moved = std::move(field);
      }
    } catch (const GeometryError&) {  // the moved pair has no crossing-free field: the plain one stands
    } catch (const InvalidInput&) {   // the moved C1 is not simple (rounding at a near-touch)
    }
  };
  run_both(run_plain, run_moved);  // the plain pass's InvalidInput (bad options, curves apart) first
  if (!moved) {
    if (plain) return std::move(*plain);
    throw GeometryError(why);
  }
  if (!plain) return std::move(*moved);
  const Points2Ref a = c1.topRows(n1), b = c2.topRows(n2);
  const CurveIndex ia = Unchecked::build(a, options.closed), ib = Unchecked::build(b, options.closed);
  return field_qm(*moved, a, ia, b, ib, options.closed) < field_qm(*plain, a, ia, b, ib, options.closed)
             ? std::move(*moved)
             : std::move(*plain);
}

}  // namespace morphomap::detail
