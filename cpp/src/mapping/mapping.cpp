// The paper's 2D mapping: basic algorithms (minimal distance, normal, uniform) on a source curve
// and a target curve, or on each pair of segments between their intersection points (split), with
// the reverse and transform extensions around them.
#include <morphomap/crossings.hpp>
#include <morphomap/curve_geometry.hpp>
#include <morphomap/curve_queries.hpp>
#include <morphomap/laplace.hpp>
#include <morphomap/mapping.hpp>
#include <morphomap/optimal.hpp>
#include <morphomap/resample.hpp>
#include <morphomap/transform.hpp>

#include "common/finite_rows.hpp"
#include "common/interrupt_check.hpp"
#include "common/numbers.hpp"
#include "common/validation.hpp"
#include "curves/arc_curve.hpp"
#include "curves/contact.hpp"
#include "curves/inside.hpp"
#include "curves/unchecked.hpp"
#include "diffusion/laplace_unchecked.hpp"
#include "mapping/curve_job.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <memory>
#include <string>
#include <tuple>
#include <utility>
#include <vector>

namespace morphomap {

using detail::kNaN;
// After map_curves' entry checks, its curves and the pieces cut from them (finite, enough points)
// go to the unchecked variants; the query points are points of those curves.
using Unchecked = detail::CurveIndexUnchecked;

namespace {

using detail::ArcCurve;
using detail::basic_method;
using detail::best_anchor;
using detail::Job;
using detail::Meeting;
using detail::relative_direction;
using detail::Settings;
using detail::Vectors;

// One job with one method: the default's choice, the paper's Algorithm 1, or a basic algorithm.
Vectors run(MapMethod method, const Job& job, const std::vector<double>& start_keys, const ArcCurve& whole_source,
            const CurveIndex& whole_source_index, const Settings& settings) {
  detail::check_interrupt();
  switch (method) {
    case MapMethod::automatic:
      return detail::default_choice(job, start_keys, whole_source, whole_source_index, settings);
    case MapMethod::paper:
      return detail::paper_algorithm(job, start_keys, whole_source, whole_source_index, settings);
    default:
      return detail::forward(method, job, start_keys, settings);
  }
}

// Stacks the vectors of all jobs in the order of their keys (arc position of the start along the
// source; the reverse-diffusion vectors of "auto" fall in among the others).
Vectors gather(std::vector<Vectors>& parts) {
  Index total = 0;
  for (const Vectors& v : parts) total += v.starts.rows();
  std::vector<std::pair<std::size_t, Index>> order;
  order.reserve(total);
  for (std::size_t p = 0; p < parts.size(); ++p) {
    for (Index i = 0; i < parts[p].starts.rows(); ++i) order.emplace_back(p, i);
  }
  std::stable_sort(order.begin(), order.end(), [&](const auto& a, const auto& b) {
    return parts[a.first].keys[a.second] < parts[b.first].keys[b.second];
  });
  Vectors all;
  all.starts.resize(total, 2);
  all.ends.resize(total, 2);
  for (Index r = 0; r < total; ++r) {
    const Vectors& v = parts[order[r].first];
    all.starts.row(r) = v.starts.row(order[r].second);
    all.ends.row(r) = v.ends.row(order[r].second);
    all.methods.push_back(v.methods[order[r].second]);
  }
  return all;
}

// One end of a piece: a meeting's end, or an end of open curves.
struct End {
  double s, t;  // arc positions on source and target
  Vec2 p, q;    // the points there
  bool meeting;
};

// Where a pair splits: the one rule behind the mapping and split_curves. The meetings kept (none:
// the whole curves map as one), the pieces between them, the source rows each piece maps (in
// order along it) and the rows on contact stretches; a row that is (within rounding) a crossing
// belongs to no piece, as the crossings map onto themselves.
struct Split {
  CurveIntersections crossings;
  std::vector<Meeting> meetings;
  std::vector<std::pair<End, End>> pieces;
  std::vector<std::vector<Index>> members;
  std::vector<char> on_stretch;
};

Split split_pair(const ArcCurve& source, const ArcCurve& target, const CurveIndex& source_index,
                 const CurveIndex& target_index, bool closed, bool split, bool find_crossings, double contact_tolerance,
                 int direction) {
  Split out;
  const Index n = source.size();
  out.on_stretch.assign(n, 0);
  if (split || find_crossings) {
    out.crossings = detail::curve_intersections_unchecked(source.points(), target.points(), closed);
  }
  // Where the curves meet: the crossings (when splitting) and, always, the stretches where they
  // touch or run together, which no region between them spans.
  const double tolerance =
      contact_tolerance >= 0.0 ? contact_tolerance : detail::default_contact_tolerance(source, target);
  const std::vector<Meeting> found = detail::find_meetings(source, target, source_index, target_index,
                                                           split ? out.crossings : CurveIntersections(), tolerance);
  bool in_order = true;
  std::vector<Meeting> meetings = detail::meetings_in_order(found, target, direction, &in_order);
  const bool contact = std::any_of(found.begin(), found.end(), [](const Meeting& m) { return !m.crossing; });
  // Crossings alone that do not pair up in order: map the whole curves (diffusion handles
  // crossing curves as one region).
  if (!in_order && !contact) meetings.clear();
  // A closed pair that meets at one point only has no two pieces to pair: the piece between the
  // point and itself would be the whole curve onto a point of the target. Map the whole curves.
  if (closed && meetings.size() == 1 && meetings[0].source_begin == meetings[0].source_end) meetings.clear();
  out.meetings = meetings;
  if (meetings.empty()) return out;

  // Each piece runs from the end of one meeting to the start of the next (open curves also from
  // their start to the first and from the last to their end) and maps onto the target between
  // the same two meetings.
  const Index count = static_cast<Index>(meetings.size());
  // A crossing is one point on both curves: the same bits in both pieces (computed on each curve it
  // can differ in the last bit, and the loop that joins the pieces then has an edge of 1e-16 that
  // the 2D mesher crashed on).
  auto begin_of = [&](const Meeting& m, double shift) {
    return End{m.source_begin + shift, m.target_begin, m.source_point_begin,
               m.crossing ? m.source_point_begin : m.target_point_begin, true};
  };
  auto end_of = [&](const Meeting& m) {
    return End{m.source_end, m.target_end, m.source_point_end, m.crossing ? m.source_point_end : m.target_point_end,
               true};
  };
  if (closed) {
    for (Index p = 0; p < count; ++p) {
      out.pieces.emplace_back(end_of(meetings[p]),
                              begin_of(meetings[(p + 1) % count], p + 1 == count ? source.length() : 0.0));
    }
  } else {
    const Index last = n - 1;
    out.pieces.emplace_back(
        End{0.0, 0.0, source.points().row(0).transpose(), target.points().row(0).transpose(), false},
        begin_of(meetings[0], 0.0));
    for (Index p = 0; p + 1 < count; ++p) out.pieces.emplace_back(end_of(meetings[p]), begin_of(meetings[p + 1], 0.0));
    out.pieces.emplace_back(end_of(meetings[count - 1]),
                            End{source.length(), target.length(), source.points().row(last).transpose(),
                                target.points().row(target.size() - 1).transpose(), false});
  }
  for (const Meeting& m : meetings) {
    if (m.crossing) continue;
    for (Index v = m.first_vertex;; v = (v + 1) % n) {
      out.on_stretch[v] = 1;
      if (v == m.last_vertex) break;
    }
  }
  // Each other source point goes to the piece it lies in; a point that is (within rounding) a
  // crossing stays where it is, as the crossings do.
  const double coincident = 1e-12 * source.length();
  std::vector<double> begins(count);
  for (Index p = 0; p < count; ++p) begins[p] = meetings[p].source_begin;
  out.members.resize(out.pieces.size());
  for (Index i = 0; i < n; ++i) {
    if (out.on_stretch[i]) continue;
    const double s = source.arc(i);
    const Index after = std::upper_bound(begins.begin(), begins.end(), s) - begins.begin();
    bool on_crossing = false;
    for (Index c : {after - 1, after}) {
      if (c >= 0 && c < count && meetings[c].crossing && source.between(s, meetings[c].source_begin) <= coincident) {
        on_crossing = true;
      }
    }
    if (on_crossing) continue;
    out.members[closed ? (after == 0 ? count - 1 : after - 1) : after].push_back(i);
  }
  // Along the piece: the closing piece of a closed curve wraps past the first point.
  for (std::size_t p = 0; p < out.pieces.size(); ++p) {
    const double from = out.pieces[p].first.s;
    std::stable_sort(out.members[p].begin(), out.members[p].end(), [&](Index a, Index b) {
      return source.forward(from, source.arc(a)) < source.forward(from, source.arc(b));
    });
  }
  return out;
}

// The open polylines of piece p as its job maps them: the source from one end through its member
// rows to the other, the target between the same two ends, walked in the source's direction.
std::pair<Points2, Points2> piece_polylines(const ArcCurve& source, const ArcCurve& target, const Split& split,
                                            std::size_t p, int direction) {
  const End &from = split.pieces[p].first, &to = split.pieces[p].second;
  const std::vector<Index>& m = split.members[p];
  const Index offset = from.meeting ? 1 : 0;
  Points2 piece_source(offset + m.size() + (to.meeting ? 1 : 0), 2);
  if (from.meeting) piece_source.row(0) = from.p.transpose();
  for (std::size_t j = 0; j < m.size(); ++j) piece_source.row(offset + j) = source.points().row(m[j]);
  if (to.meeting) piece_source.row(piece_source.rows() - 1) = to.p.transpose();
  Points2 piece_target = source.closed() && direction < 0 ? Points2(target.piece(to.t, from.t).colwise().reverse())
                                                          : target.piece(from.t, to.t);
  // The pieces end exactly at the meetings (the target's are found by arc length).
  if (from.meeting) piece_target.row(0) = from.q.transpose();
  if (to.meeting) piece_target.row(piece_target.rows() - 1) = to.q.transpose();
  return {std::move(piece_source), std::move(piece_target)};
}

// The query index of `curve` (a checked curve): `given` (a PreparedCurve's, not owned) where it
// indexes exactly these points, else one built here. A prepared curve's index covers the points
// that take part of the curve as given; `curve` is always a leading part of those rows, so equal
// sizes mean equal indices (and equal answers, bit for bit).
std::shared_ptr<const CurveIndex> index_of(const Points2Ref& curve, bool closed, const CurveIndex* given) {
  if (given != nullptr && given->closed() == closed && given->size() == detail::curve_size(curve, closed)) {
    return std::shared_ptr<const CurveIndex>(std::shared_ptr<const CurveIndex>(), given);
  }
  return std::make_shared<const CurveIndex>(Unchecked::build(curve, closed));
}

// source_given, target_given: the curves' indices where the caller has them (see index_of).
Vectors map_directed(const Points2& source_points, const Points2& target_points, MapMethod method, bool closed,
                     bool split, const std::optional<std::pair<Vec2, Vec2>>& anchors, const Settings& settings,
                     const CurveIndex* source_given, const CurveIndex* target_given) {
  const ArcCurve source = ArcCurve::unchecked(source_points, closed);
  const ArcCurve target = ArcCurve::unchecked(target_points, closed);
  const auto whole_source_index = index_of(source.points(), closed, source_given);
  const auto whole_target_index = index_of(target.points(), closed, target_given);
  const Index n = source.size();
  const bool wants_normals =
      method == MapMethod::normal || method == MapMethod::automatic || method == MapMethod::paper;
  const Points2 source_normals = wants_normals ? detail::normals_unchecked(source.points(), closed) : Points2();
  const int direction = closed ? relative_direction(source, target) : 1;

  const Split pieces_of = split_pair(source, target, *whole_source_index, *whole_target_index, closed, split,
                                     closed && method == MapMethod::uniform, settings.contact_tolerance, direction);
  const CurveIntersections& crossings = pieces_of.crossings;
  const Index k = crossings.points.rows();
  const std::vector<Meeting>& meetings = pieces_of.meetings;

  auto add_starts = [&](Job& job, const std::vector<Index>& points, Index first_row) {
    for (std::size_t j = 0; j < points.size(); ++j) job.start_rows.push_back(first_row + j);
    if (wants_normals) {
      job.normals.resize(points.size(), 2);
      for (std::size_t j = 0; j < points.size(); ++j) job.normals.row(j) = source_normals.row(points[j]);
    }
  };

  if (meetings.empty()) {
    Job job;
    job.source = source.points();
    job.source_closed = closed;
    std::vector<Index> all(n);
    std::vector<double> keys(n);
    for (Index i = 0; i < n; ++i) all[i] = i, keys[i] = source.arc(i);
    add_starts(job, all, 0);
    job.target = target.points();
    job.target_closed = closed;
    job.source_index = whole_source_index;
    job.target_index = whole_target_index;
    if (method == MapMethod::uniform) {
      double from = 0.0;  // source anchor
      if (!closed) {
        job.anchor = 0.0;
      } else if (k > 0) {
        from = crossings.arc_lengths1[0];
        job.anchor = crossings.arc_lengths2[0];
      } else if (anchors) {
        from = Unchecked::closest_points(*whole_source_index, anchors->first.transpose()).arc_lengths[0];
        job.anchor = Unchecked::closest_points(*whole_target_index, anchors->second.transpose()).arc_lengths[0];
      } else {
        job.anchor = best_anchor(source, target, direction);
      }
      job.direction = direction;
      job.fractions.resize(n);
      for (Index i = 0; i < n; ++i) job.fractions[i] = source.forward(from, source.arc(i)) / source.length();
    }
    std::vector<Vectors> parts{run(method, job, keys, source, *whole_source_index, settings)};
    return gather(parts);
  }

  // Split (split_pair): a crossing maps onto itself and is a start point of its own; the source
  // points on a contact stretch map to their closest point on the target; each piece maps on its
  // own.
  std::vector<Vectors> parts(1);
  Vectors& fixed = parts[0];
  std::vector<Vec2> fixed_starts, fixed_ends;
  std::vector<Method> fixed_methods;
  const Method crossing_method =
      basic_method(method == MapMethod::automatic || method == MapMethod::paper ? MapMethod::normal : method);
  for (const Meeting& m : meetings) {
    if (!m.crossing) continue;
    fixed_starts.push_back(m.source_point_begin), fixed_ends.push_back(m.source_point_begin);
    fixed.keys.push_back(m.source_begin), fixed_methods.push_back(crossing_method);
  }
  std::vector<Index> stretch_rows;
  for (Index i = 0; i < n; ++i) {
    if (pieces_of.on_stretch[i]) stretch_rows.push_back(i);
  }
  if (!stretch_rows.empty()) {
    const Points2 queries = source.points()(stretch_rows, Eigen::all);
    const Points2 closest = Unchecked::closest_points(*whole_target_index, queries).points;
    for (std::size_t j = 0; j < stretch_rows.size(); ++j) {
      fixed_starts.push_back(queries.row(j).transpose()), fixed_ends.push_back(closest.row(j).transpose());
      fixed.keys.push_back(source.arc(stretch_rows[j])), fixed_methods.push_back(Method::minimal_distance);
    }
  }
  fixed.starts.resize(fixed_starts.size(), 2);
  fixed.ends.resize(fixed_ends.size(), 2);
  for (std::size_t j = 0; j < fixed_starts.size(); ++j) {
    fixed.starts.row(j) = fixed_starts[j].transpose(), fixed.ends.row(j) = fixed_ends[j].transpose();
  }
  fixed.methods = std::move(fixed_methods);

  for (std::size_t p = 0; p < pieces_of.pieces.size(); ++p) {
    const std::vector<Index>& m = pieces_of.members[p];
    if (m.empty()) continue;
    const End &from = pieces_of.pieces[p].first, &to = pieces_of.pieces[p].second;
    Job job;
    std::tie(job.source, job.target) = piece_polylines(source, target, pieces_of, p, direction);
    add_starts(job, m, from.meeting ? 1 : 0);
    job.shared_begin = from.meeting, job.shared_end = to.meeting;
    if (method == MapMethod::uniform) {
      const double length = to.s - from.s;
      job.fractions.resize(m.size());
      for (std::size_t j = 0; j < m.size(); ++j) {
        const double along = closed ? source.forward(from.s, source.arc(m[j])) : source.arc(m[j]) - from.s;
        job.fractions[j] = length > 0 ? along / length : 0.0;
      }
    }
    std::vector<double> keys(m.size());
    for (std::size_t j = 0; j < m.size(); ++j) keys[j] = source.arc(m[j]);
    parts.push_back(run(method, job, keys, source, *whole_source_index, settings));
  }
  Vectors all = gather(parts);
  // The default chose each piece crossing-free; vectors of two pieces can still cross where their
  // regions overlap (a piece's vectors reaching past a split point): said, never returned.
  if (method == MapMethod::automatic) {
    const auto pairs = crossing_pairs(all.starts, all.ends);
    if (!pairs.empty()) {
      const Vec2 at = all.starts.row(pairs[0].first).transpose();
      throw GeometryError("map_curves: the fields of the pieces between the curves' split points cross each other (" +
                          std::to_string(pairs.size()) + " crossing pairs, the first from (" + std::to_string(at.x()) +
                          ", " + std::to_string(at.y()) + ")); try method='best' or split=False");
    }
  }
  return all;
}

// Puts the finite rows of points onto the curve (their closest points).
void project_onto(Points2& points, const Points2Ref& curve, bool closed, const CurveIndex* given) {
  const std::vector<Index> rows = detail::finite_rows(points);
  if (rows.empty()) return;
  const Points2 queries = points(rows, Eigen::all);
  const Points2 on_curve = Unchecked::closest_points(*index_of(curve, closed, given), queries).points;
  for (std::size_t j = 0; j < rows.size(); ++j) points.row(rows[j]) = on_curve.row(j);
}

}  // namespace

void validate_options(const CurveMappingOptions& options) {
  const bool closed = options.closed;
  if (options.n < 0 || (options.n > 0 && options.n < (closed ? 3 : 2))) {
    detail::invalid("n", "must be 0 (use the given points) or at least " + std::string(closed ? "3" : "2") + ", got " +
                             std::to_string(options.n));
  }
  if (!(options.density_threshold >= 0.0) || !std::isfinite(options.density_threshold)) {
    detail::invalid("density_threshold", "must be a finite number >= 0 (0: off)");
  }
  detail::require_contact_tolerance(options.contact_tolerance);
  detail::require_diffusion_options(options.diffusion);
  if (options.anchor && !options.anchor->allFinite()) detail::invalid("anchor", "has a non-finite coordinate");
  if (!(options.stretch_weight >= 0.0) || !std::isfinite(options.stretch_weight)) {
    detail::invalid("stretch_weight", "must be a finite number >= 0, got " + std::to_string(options.stretch_weight));
  }
}

DisplacementField2 detail::mapped_pair(const Points2Ref& c1, Index n1, const CurveIndex* index1, const Points2Ref& c2,
                                       Index n2, const CurveIndex* index2, const CurveMappingOptions& options,
                                       const Similarity2* moved) {
  const bool closed = options.closed;
  validate_options(options);
  // Frames of one organ overlap; closed curves that neither cross nor nest are the wrong pair
  // (other units, another offset), whatever a method would make of them.
  // (Each curve's point farthest from the other decides: a touching point would not.)
  auto farthest = [](const Points2Ref& points, const Points2Ref& curve, const CurveIndex* given) -> Vec2 {
    Index at = 0;
    Unchecked::closest_points(*index_of(curve, true, given), points).distances.maxCoeff(&at);
    return points.row(at).transpose();
  };
  if (closed && detail::curve_intersections_unchecked(c1.topRows(n1), c2.topRows(n2), true).points.rows() == 0 &&
      !detail::inside(farthest(c1.topRows(n1), c2.topRows(n2), index2), c2.topRows(n2)) &&
      !detail::inside(farthest(c2.topRows(n2), c1.topRows(n1), index1), c1.topRows(n1))) {
    detail::invalid("c2",
                    "lies apart from c1 (the curves neither cross nor enclose one another): consecutive "
                    "frames of one organ overlap; check their units and offsets");
  }
  Points2 a = options.n > 0 ? resample(c1, options.n, closed) : Points2(c1.topRows(n1));
  const Points2 b = options.n > 0 ? resample(c2, options.n, closed) : Points2(c2.topRows(n2));

  Similarity2 similarity;
  if (options.transform) {
    similarity = align_curves(a, b, closed);
    a = similarity.apply(a);
  } else if (moved != nullptr) {
    similarity = *moved;
    a = similarity.apply(a);
  }
  const bool transformed = options.transform || moved != nullptr;
  // Resampled or moved curves are new curves: checked once here as the core's functions check
  // theirs (the given ones passed require_simple_curve, at the entry or when prepared).
  const bool derived = options.n > 0 || transformed;
  if (derived) {
    detail::require_curve(a, closed, "c1");
    detail::require_curve(b, closed, "c2");
  }
  std::optional<std::pair<Vec2, Vec2>> anchors;
  if (options.anchor) {
    Points2 anchor = options.anchor->transpose();
    if (transformed) anchor = similarity.apply(anchor);
    const Vec2 on_c1 = closest_points(anchor, a, closed).points.row(0).transpose();
    const Vec2 on_c2 = closest_points(on_c1.transpose(), b, closed).points.row(0).transpose();
    anchors = options.reverse ? std::make_pair(on_c2, on_c1) : std::make_pair(on_c1, on_c2);
  }

  Settings settings;
  settings.density_threshold = options.density_threshold;
  settings.contact_tolerance = options.contact_tolerance;
  settings.diffusion = options.diffusion;
  settings.pair_points = a.rows() + b.rows();
  settings.stretch_weight = options.stretch_weight;
  settings.simple_curves = !derived;
  // The given curves' indices serve where the mapping runs on those curves (not resampled or moved).
  const CurveIndex* index_a = derived ? nullptr : index1;
  const CurveIndex* index_b = options.n > 0 ? nullptr : index2;
  Vectors v = options.reverse
                  ? map_directed(b, a, options.method, closed, options.split, anchors, settings, index_b, index_a)
                  : map_directed(a, b, options.method, closed, options.split, anchors, settings, index_a, index_b);
  DisplacementField2 field;
  field.starts = std::move(options.reverse ? v.ends : v.starts);
  field.ends = std::move(options.reverse ? v.starts : v.ends);
  field.methods = std::move(v.methods);
  if (options.reverse) {
    for (Method& m : field.methods) m = reversed(m);
  }
  if (transformed) field.starts = similarity.apply_inverse(field.starts);
  // Resampled curves cut the corners of the given ones: the points found on them go onto the
  // curves the caller passed, so that quality(field, c1, c2) measures the field on those.
  if (options.n > 0) {
    project_onto(field.starts, c1.topRows(n1), closed, index1);
    project_onto(field.ends, c2.topRows(n2), closed, index2);
  }
  return field;
}

DisplacementField2 map_curves(const Points2Ref& c1, const Points2Ref& c2, const CurveMappingOptions& options) {
  const Index n1 = detail::require_simple_curve(c1, options.closed, "c1");
  const Index n2 = detail::require_simple_curve(c2, options.closed, "c2");
  return detail::mapped_choice(c1, n1, nullptr, c2, n2, nullptr, options);
}

DisplacementField2 map_curves(const PreparedCurve& c1, const PreparedCurve& c2, const CurveMappingOptions& options) {
  c1.require_closed(options.closed, "c1");
  c2.require_closed(options.closed, "c2");
  const Points2& p1 = c1.points();
  const Points2& p2 = c2.points();
  return detail::mapped_choice(p1, detail::curve_size(p1, options.closed), &c1.index(), p2,
                               detail::curve_size(p2, options.closed), &c2.index(), options);
}

CurveSplit split_curves(const Points2Ref& c1, const Points2Ref& c2, bool closed, bool split, double contact_tolerance) {
  const Index n1 = detail::require_simple_curve(c1, closed, "c1");
  const Index n2 = detail::require_simple_curve(c2, closed, "c2");
  detail::require_contact_tolerance(contact_tolerance);
  const ArcCurve source = ArcCurve::unchecked(c1.topRows(n1), closed);
  const ArcCurve target = ArcCurve::unchecked(c2.topRows(n2), closed);
  const int direction = closed ? relative_direction(source, target) : 1;
  const Split found =
      split_pair(source, target, Unchecked::build(source.points(), closed), Unchecked::build(target.points(), closed),
                 closed, split, false, contact_tolerance, direction);
  CurveSplit out;
  out.c1 = source.points(), out.c2 = target.points();
  out.closed = closed;
  out.direction = direction;
  if (found.meetings.empty()) {  // one piece: the whole pair
    CurvePiece whole;
    whole.source = source.points(), whole.target = target.points();
    whole.source_length = source.length(), whole.target_length = target.length();
    out.pieces.push_back(std::move(whole));
    return out;
  }
  for (std::size_t p = 0; p < found.pieces.size(); ++p) {
    const End &from = found.pieces[p].first, &to = found.pieces[p].second;
    CurvePiece piece;
    std::tie(piece.source, piece.target) = piece_polylines(source, target, found, p, direction);
    piece.begin_meeting = from.meeting, piece.end_meeting = to.meeting;
    piece.source_begin = source.wrap(from.s), piece.source_length = to.s - from.s;
    piece.target_begin = target.wrap(from.t);
    piece.target_length = !closed         ? to.t - from.t
                          : direction > 0 ? target.forward(from.t, to.t)
                                          : target.forward(to.t, from.t);
    out.pieces.push_back(std::move(piece));
  }
  return out;
}

PieceLabels piece_labels(const CurveSplit& split, const Points2Ref& points, bool on_c1) {
  if (points.cols() != 2) detail::invalid("points", "expected 2 columns");
  const ArcCurve curve(on_c1 ? split.c1 : split.c2, split.closed, on_c1 ? "c1" : "c2");
  PieceLabels labels;
  labels.piece.assign(points.rows(), -1);
  labels.along = Vector::Constant(points.rows(), kNaN);
  std::vector<Index> rows;
  for (Index i = 0; i < points.rows(); ++i) {
    if (points.row(i).allFinite()) rows.push_back(i);
  }
  if (rows.empty()) return labels;
  const Points2 queries = points(rows, Eigen::all);
  const Vector arcs = CurveIndex(curve.points(), split.closed).closest_points(queries).arc_lengths;
  // Within rounding of a meeting point is at the meeting (the crossings' own vectors lie there).
  const double coincident = 1e-12 * curve.length();
  const bool whole = split.pieces.size() == 1 && !split.pieces[0].begin_meeting && !split.pieces[0].end_meeting;
  for (std::size_t j = 0; j < rows.size(); ++j) {
    for (std::size_t p = 0; p < split.pieces.size(); ++p) {
      const CurvePiece& piece = split.pieces[p];
      const double begin = on_c1 ? piece.source_begin : piece.target_begin;
      const double length = on_c1 ? piece.source_length : piece.target_length;
      const int way = on_c1 ? 1 : split.direction;
      double along = 0.0;
      if (whole) {
        along = split.closed && way < 0 ? curve.forward(arcs[j], 0.0) : arcs[j];
      } else if (split.closed) {
        along = way > 0 ? curve.forward(begin, arcs[j]) : curve.forward(arcs[j], begin);
      } else {
        along = arcs[j] - begin;
      }
      const bool after_begin = piece.begin_meeting ? along > coincident : along >= -coincident;
      const bool before_end = piece.end_meeting ? along < length - coincident : along <= length + coincident;
      if (whole || (after_begin && before_end)) {
        labels.piece[rows[j]] = static_cast<Index>(p);
        labels.along[rows[j]] = along;
        break;
      }
    }
  }
  return labels;
}

}  // namespace morphomap
