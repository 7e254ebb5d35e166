#include "curves/contact.hpp"

#include "curves/unchecked.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace morphomap::detail {

namespace {

double median_segment(const ArcCurve& curve) {
  const Index segments = curve.closed() ? curve.size() : curve.size() - 1;
  std::vector<double> lengths;
  lengths.reserve(segments);
  for (Index i = 0; i < segments; ++i) {
    const double length = curve.arc(i + 1) - curve.arc(i);
    if (length > 0.0) lengths.push_back(length);
  }
  if (lengths.empty()) return 0.0;
  auto middle = lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2);
  std::nth_element(lengths.begin(), middle, lengths.end());
  return *middle;
}

// Whether every vertex of the curve strictly inside the shorter way between positions a and b is
// marked in `near`.
bool vertices_between_near(const ArcCurve& curve, double a, double b, const std::vector<char>& near) {
  const Index n = curve.size();
  if (!curve.closed()) {
    if (b < a) std::swap(a, b);
    for (Index v = curve.vertex_after(a); v < n && curve.arc(v) < b; ++v) {
      if (!near[v]) return false;
    }
    return true;
  }
  if (curve.forward(a, b) > curve.forward(b, a)) std::swap(a, b);
  const double span = curve.forward(a, b);
  Index v = curve.vertex_after(a);
  for (Index step = 0; step < n; ++step, ++v) {
    const Index w = v % n;
    const double d = curve.forward(a, curve.arc(w));
    if (d >= span) break;
    if (d > 0.0 && !near[w]) return false;
  }
  return true;
}

}  // namespace

double default_contact_tolerance(const ArcCurve& source, const ArcCurve& target) {
  return 0.01 * std::min(median_segment(source), median_segment(target));
}

std::vector<Meeting> find_meetings(const ArcCurve& source, const ArcCurve& target, const CurveIndex& source_index,
                                   const CurveIndex& target_index, const CurveIntersections& crossings,
                                   double tolerance) {
  const Index n = source.size();
  const bool closed = source.closed();
  // The points of checked curves are finite: no query to check.
  const CurveHits to_target = CurveIndexUnchecked::closest_points(target_index, source.points());
  const CurveHits to_source = CurveIndexUnchecked::closest_points(source_index, target.points());
  std::vector<char> near_source(n), near_target(target.size());
  for (Index i = 0; i < n; ++i) near_source[i] = to_target.distances[i] <= tolerance;
  for (Index j = 0; j < target.size(); ++j) near_target[j] = to_source.distances[j] <= tolerance;

  // Segment i of the source (vertex i to the next) lies along the target when both ends are near
  // it and their closest points on the target are neighbours there too.
  const Index segments = closed ? n : n - 1;
  std::vector<char> joined(segments, 0);
  for (Index i = 0; i < segments; ++i) {
    const Index k = (i + 1) % n;
    if (!near_source[i] || !near_source[k]) continue;
    const double a = target.wrap(to_target.arc_lengths[i]), b = target.wrap(to_target.arc_lengths[k]);
    const double step = source.arc(i + 1) - source.arc(i);
    if (target.between(a, b) > 2.0 * (step + tolerance)) continue;
    joined[i] = vertices_between_near(target, a, b, near_target);
  }

  std::vector<Meeting> runs;
  auto add_run = [&](Index first, Index last) {
    Meeting meeting;
    meeting.first_vertex = first;
    meeting.last_vertex = last;
    meeting.source_begin = source.arc(first);
    meeting.source_end = meeting.source_begin + source.forward(source.arc(first), source.arc(last));
    meeting.target_begin = target.wrap(to_target.arc_lengths[first]);
    meeting.target_end = target.wrap(to_target.arc_lengths[last]);
    meeting.source_point_begin = source.points().row(first).transpose();
    meeting.source_point_end = source.points().row(last).transpose();
    meeting.target_point_begin = to_target.points.row(first).transpose();
    meeting.target_point_end = to_target.points.row(last).transpose();
    runs.push_back(meeting);
  };
  if (!closed) {
    for (Index i = 0; i < n; ++i) {
      if (!near_source[i]) continue;
      const Index first = i;
      while (i < segments && joined[i]) ++i;
      add_run(first, i);
    }
  } else {
    const auto gap = std::find(joined.begin(), joined.end(), 0);
    if (gap == joined.end()) {
      add_run(0, n - 1);  // the curves coincide all round
    } else {
      // Start after a segment that is not joined, so that no run is cut in two by the scan.
      const Index z = gap - joined.begin();
      for (Index k = 0; k < n; ++k) {
        const Index v = (z + 1 + k) % n;
        if (!near_source[v]) continue;
        while (k < n - 1 && joined[(z + 1 + k) % n]) ++k;
        add_run(v, (z + 1 + k) % n);
      }
    }
  }
  std::sort(runs.begin(), runs.end(),
            [](const Meeting& a, const Meeting& b) { return a.source_begin < b.source_begin; });

  std::vector<Meeting> meetings = runs;
  const double length = source.length();
  auto on_run = [&](double s) {
    const auto after = std::upper_bound(runs.begin(), runs.end(), s + tolerance,
                                        [](double x, const Meeting& m) { return x < m.source_begin; });
    if (after != runs.begin() && s <= std::prev(after)->source_end + tolerance) return true;
    // A run over the first point of a closed curve also covers the start of the curve.
    return closed && !runs.empty() && s + length <= runs.back().source_end + tolerance;
  };
  for (Index j = 0; j < crossings.points.rows(); ++j) {
    const double s = crossings.arc_lengths1[j];
    if (on_run(s)) continue;
    Meeting meeting;
    meeting.crossing = true;
    meeting.source_begin = meeting.source_end = s;
    meeting.target_begin = meeting.target_end = crossings.arc_lengths2[j];
    const Vec2 p = crossings.points.row(j).transpose();
    meeting.source_point_begin = meeting.source_point_end = meeting.target_point_begin = meeting.target_point_end = p;
    meetings.push_back(meeting);
  }
  std::stable_sort(meetings.begin(), meetings.end(),
                   [](const Meeting& a, const Meeting& b) { return a.source_begin < b.source_begin; });
  return meetings;
}

std::vector<Meeting> meetings_in_order(const std::vector<Meeting>& meetings, const ArcCurve& target, int direction,
                                       bool* all_in_order) {
  std::vector<Meeting> kept;
  *all_in_order = true;
  if (meetings.empty()) return kept;
  double origin = 0.0;  // the first kept meeting's start
  // Distance walked along the target (in direction) from the first meeting's start.
  auto along = [&](double t) {  // only once a meeting is kept
    if (!target.closed()) return t - origin;
    return direction > 0 ? target.forward(origin, t) : target.forward(t, origin);
  };
  double last = -std::numeric_limits<double>::infinity();
  const double length = target.length();
  for (const Meeting& meeting : meetings) {
    // Along the target from the stretch's start to its end, in direction, or against it: the
    // way whose length is nearer to the stretch's length on the source. A stretch that runs
    // against it (the curves touch there from opposite sides) cannot be walked in order with the
    // others and is left out.
    double span = meeting.target_end - meeting.target_begin;
    if (target.closed()) {
      const double with = direction > 0 ? target.forward(meeting.target_begin, meeting.target_end)
                                        : target.forward(meeting.target_end, meeting.target_begin);
      const double on_source = meeting.source_end - meeting.source_begin;
      span = std::abs(with - on_source) <= std::abs(length - with - on_source) ? with : -(length - with);
    }
    if (!meeting.crossing && span < -1e-12 * length) {
      *all_in_order = false;
      continue;
    }
    span = std::max(span, 0.0);
    const double begin = kept.empty() ? 0.0 : along(meeting.target_begin);
    if ((kept.empty() || begin > last) && begin + span < length + 1e-12 * length) {
      if (kept.empty()) origin = meeting.target_begin;
      kept.push_back(meeting);
      last = begin + span;
    } else {
      *all_in_order = false;
    }
  }
  return kept;
}

}  // namespace morphomap::detail
