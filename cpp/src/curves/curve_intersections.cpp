#include <morphomap/curve_queries.hpp>

#include "common/distinct_points.hpp"
#include "common/numbers.hpp"
#include "common/segment_pairs.hpp"
#include "common/validation.hpp"
#include "curves/unchecked.hpp"

#include <CGAL/Exact_rational.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <numeric>
#include <tuple>
#include <vector>

namespace morphomap {
namespace {

using detail::orient;
using detail::Point;

// One curve without repeats, with what the crossing search needs.
struct Curve {
  Points2 q;
  std::vector<Point> p;
  Vector s;                    // arc length at each point
  std::vector<Index> segment;  // input segment index of each segment
  Index segments;

  // `checked`: the points passed require_curve already.
  Curve(const Points2Ref& points, bool closed, const char* name, bool checked)
      : q(checked ? detail::drop_repeats(points, closed, name) : detail::without_repeats(points, closed, name)) {
    const Index m = q.rows();
    segments = closed ? m : m - 1;
    p.resize(m);
    for (Index k = 0; k < m; ++k) p[k] = detail::point_at(q, k);
    s.resize(m + 1);  // s(m): the perimeter, the end of the closing segment
    s(0) = 0.0;
    for (Index k = 0; k < m; ++k) s(k + 1) = s(k) + (q.row((k + 1) % m) - q.row(k)).norm();
    segment = detail::distinct_points(points, detail::curve_size(points, closed), closed).segment;
  }
  const Point& start(Index k) const { return p[k]; }
  const Point& end(Index k) const { return p[(k + 1) % p.size()]; }
  std::vector<detail::SegmentBox> boxes() const {
    std::vector<detail::SegmentBox> b;
    b.reserve(segments);
    for (Index k = 0; k < segments; ++k) b.emplace_back(start(k), end(k), k);
    return b;
  }
};

// Sign of orient(a, b, c + εv), v = (1, δ), δ ≪ 1: the exact sign, or when c lies on the line
// ab, the sign of cross(b - a, v).
int orient_shifted_point(const Point& a, const Point& b, const Point& c) {
  const int o = orient(a, b, c);
  if (o != 0) return o;
  return b.y() != a.y() ? -detail::sign(b.y() - a.y()) : detail::sign(b.x() - a.x());
}

// Sign of orient(a + εv, b + εv, c): when zero unshifted, -sign(cross(b - a, v)).
int orient_shifted_segment(const Point& a, const Point& b, const Point& c) {
  const int o = orient(a, b, c);
  if (o != 0) return o;
  return b.y() != a.y() ? detail::sign(b.y() - a.y()) : -detail::sign(b.x() - a.x());
}

double cross(const Point& a, const Point& b, const Point& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

// Where segment ab meets the line cd: t along ab, exactly 0 or 1 when a or b lies on the line.
double crossing_parameter(const Point& a, const Point& b, const Point& c, const Point& d) {
  if (orient(c, d, a) == 0) return 0.0;
  if (orient(c, d, b) == 0) return 1.0;
  const double oa = cross(c, d, a), ob = cross(c, d, b);
  const double t = oa != ob ? oa / (oa - ob) : 0.5;
  return std::clamp(t, 0.0, 1.0);
}

// Parameter of the point c, known to lie on segment ab, along ab.
double projection_parameter(const Point& a, const Point& b, const Point& c) {
  const double dx = b.x() - a.x(), dy = b.y() - a.y();
  const double t = ((c.x() - a.x()) * dx + (c.y() - a.y()) * dy) / (dx * dx + dy * dy);
  return std::clamp(t, 0.0, 1.0);
}

struct Crossing {
  Vec2 point;
  Index seg1, seg2;  // segments of the curves without repeats
  double s1, s2;
  Index i, j;  // the segments as found, before a crossing at t = 1 moved to the next one
};

// The exact intersection point of segment i of c1 with the line of segment j of c2.
std::array<CGAL::Exact_rational, 2> exact_point(const Curve& c1, Index i, const Curve& c2, Index j) {
  using Q = CGAL::Exact_rational;
  const Point &p1 = c1.start(i), &p2 = c1.end(i), &q1 = c2.start(j), &q2 = c2.end(j);
  const auto cross_q = [](const Point& a, const Point& b, const Point& c) -> Q {
    return (Q(b.x()) - Q(a.x())) * (Q(c.y()) - Q(a.y())) - (Q(b.y()) - Q(a.y())) * (Q(c.x()) - Q(a.x()));
  };
  const Q o1 = cross_q(q1, q2, p1), o2 = cross_q(q1, q2, p2);
  const Q t = o1 / (o1 - o2);
  return {Q(p1.x()) + t * (Q(p2.x()) - Q(p1.x())), Q(p1.y()) + t * (Q(p2.y()) - Q(p1.y()))};
}

// A crossing at parameter t of segment k, moved to the start of the next segment when t == 1 so
// that a crossing at a vertex has one description (on a closed curve, the first point is at 0).
void normalise(Index& k, double& t, const Curve& c, bool closed) {
  if (t == 1.0 && (closed || k + 1 < c.segments)) {
    k = (k + 1) % c.segments;
    t = 0.0;
  }
}

Crossing make_crossing(const Curve& c1, Index i, const Curve& c2, Index j, bool closed) {
  const Point &p1 = c1.start(i), &p2 = c1.end(i), &q1 = c2.start(j), &q2 = c2.end(j);
  double t1 = crossing_parameter(p1, p2, q1, q2);
  double t2 = crossing_parameter(q1, q2, p1, p2);
  // Exact vertices where possible; the other parameter then from that vertex alone, so that
  // every crossing found at one vertex gets the same numbers.
  Point at;
  if (t1 == 0.0 || t1 == 1.0) {
    at = t1 == 0.0 ? p1 : p2;
    if (t2 != 0.0 && t2 != 1.0) t2 = projection_parameter(q1, q2, at);
  } else if (t2 == 0.0 || t2 == 1.0) {
    at = t2 == 0.0 ? q1 : q2;
    t1 = projection_parameter(p1, p2, at);
  } else {
    at = Point(p1.x() + t1 * (p2.x() - p1.x()), p1.y() + t1 * (p2.y() - p1.y()));
  }
  const auto arc = [](const Curve& c, Index k, double t) {
    return t == 0.0 ? c.s(k) : c.s(k) + t * (c.s(k + 1) - c.s(k));
  };
  const Index found_i = i, found_j = j;
  normalise(i, t1, c1, closed);
  normalise(j, t2, c2, closed);
  return {Vec2(at.x(), at.y()), i, j, arc(c1, i, t1), arc(c2, j, t2), found_i, found_j};
}

// Whether segment i of c1 and segment j of c2 cross once c2 is shifted by εv: with every
// orientation nonzero, they either cross properly or not at all.
bool shifted_cross(const Curve& c1, Index i, const Curve& c2, Index j) {
  const Point &p1 = c1.start(i), &p2 = c1.end(i), &q1 = c2.start(j), &q2 = c2.end(j);
  return orient_shifted_point(p1, p2, q1) != orient_shifted_point(p1, p2, q2) &&
         orient_shifted_segment(q1, q2, p1) != orient_shifted_segment(q1, q2, p2);
}

// Drops pairs of crossings at one point that are neighbours in order along both curves: a touch
// that the shift turned into two crossings. `order` lists crossings along c1.
std::vector<Index> drop_touches(const Curve& c1, const Curve& c2, const std::vector<Crossing>& x,
                                std::vector<Index> order, bool closed) {
  // Same point, decided exactly: rounding can merge distinct points or split equal ones.
  const auto same_point = [&](const Crossing& a, const Crossing& b) {
    return exact_point(c1, a.i, c2, a.j) == exact_point(c1, b.i, c2, b.j);
  };
  for (bool changed = true; changed && order.size() >= 2;) {
    changed = false;
    const std::size_t k = order.size();
    std::vector<Index> by2(order);
    std::stable_sort(by2.begin(), by2.end(),
                     [&](Index a, Index b) { return std::tie(x[a].s2, x[a].s1) < std::tie(x[b].s2, x[b].s1); });
    std::vector<std::size_t> rank2(x.size());
    for (std::size_t r = 0; r < k; ++r) rank2[by2[r]] = r;
    const auto neighbours2 = [&](Index a, Index b) {
      const std::size_t ra = rank2[a], rb = rank2[b];
      const std::size_t lo = std::min(ra, rb), hi = std::max(ra, rb);
      return hi == lo + 1 || (closed && lo == 0 && hi == k - 1);
    };
    std::vector<char> drop(k, 0);
    const std::size_t last = closed && k > 2 ? k : k - 1;  // c1 neighbours, wrapping when closed
    for (std::size_t r = 0; r < last; ++r) {
      const std::size_t r2 = (r + 1) % k;
      const Index a = order[r], b = order[r2];
      if (drop[r] || drop[r2] || !neighbours2(a, b) || !same_point(x[a], x[b])) continue;
      drop[r] = drop[r2] = 1;
      changed = true;
    }
    std::vector<Index> kept;
    for (std::size_t r = 0; r < k; ++r) {
      if (!drop[r]) kept.push_back(order[r]);
    }
    order.swap(kept);
  }
  return order;
}

CurveIntersections intersections(const Curve& a, const Curve& b, bool closed) {
  detail::IndexPairs hits;
  detail::test_overlapping_pairs(
      a.boxes(), b.boxes(), [&](Index i, Index j) { return shifted_cross(a, i, b, j); }, &hits);

  std::vector<Crossing> x;
  x.reserve(hits.size());
  for (const auto& [i, j] : hits) x.push_back(make_crossing(a, i, b, j, closed));
  std::vector<Index> order(x.size());
  std::iota(order.begin(), order.end(), Index(0));
  std::stable_sort(order.begin(), order.end(),
                   [&](Index u, Index v) { return std::tie(x[u].s1, x[u].s2) < std::tie(x[v].s1, x[v].s2); });
  order = drop_touches(a, b, x, order, closed);

  CurveIntersections out;
  const Index k = static_cast<Index>(order.size());
  out.points.resize(k, 2);
  out.arc_lengths1.resize(k);
  out.arc_lengths2.resize(k);
  out.segments1.resize(k);
  out.segments2.resize(k);
  for (Index r = 0; r < k; ++r) {
    const Crossing& c = x[order[r]];
    out.points.row(r) = c.point;
    out.arc_lengths1(r) = c.s1;
    out.arc_lengths2(r) = c.s2;
    out.segments1(r) = a.segment[c.seg1];
    out.segments2(r) = b.segment[c.seg2];
  }
  return out;
}

}  // namespace

CurveIntersections curve_intersections(const Points2Ref& c1, const Points2Ref& c2, bool closed) {
  const Curve a(c1, closed, "c1", false), b(c2, closed, "c2", false);
  return intersections(a, b, closed);
}

CurveIntersections detail::curve_intersections_unchecked(const Points2Ref& c1, const Points2Ref& c2, bool closed) {
  const Curve a(c1, closed, "c1", true), b(c2, closed, "c2", true);
  return intersections(a, b, closed);
}

}  // namespace morphomap
