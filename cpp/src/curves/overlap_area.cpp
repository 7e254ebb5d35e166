// Area of the intersection of two simple polygons from the crossings of their boundaries.
//
// With both boundaries counter-clockwise, the boundary of A ∩ B is made of the parts of ∂A inside
// B and the parts of ∂B inside A, and its area is the boundary integral ∮ (x dy - y dx) / 2 over
// them. curve_intersections cuts both boundaries at their crossings under its symbolic shift of
// the second curve by ε(1, δ); every crossing is then proper, so inside and outside alternate from
// one piece to the next along each curve. One exact point-in-polygon test per curve, under the
// same shift, settles which pieces are inside. The result is the area for the shifted B in the
// limit ε -> 0, which is the area of A ∩ B.
#include <morphomap/curve_geometry.hpp>
#include <morphomap/curve_queries.hpp>
#include <morphomap/transform.hpp>

#include "common/numbers.hpp"
#include "common/segment_pairs.hpp"
#include "common/validation.hpp"

#include <CGAL/Exact_rational.h>

#include <algorithm>
#include <numeric>
#include <tuple>
#include <vector>

namespace morphomap {
namespace {

using detail::Point;

// The curve without repeats and counter-clockwise.
Points2 counter_clockwise(const Points2Ref& points, const char* name) {
  int turn = 0;
  Points2 q = detail::oriented_closed_curve(points, name, turn);
  if (turn < 0) q = q.colwise().reverse().eval();
  return q;
}

// Whether the point p + η·d + s·ε(1, δ) lies inside the polygon (even-odd rule, a horizontal ray
// to the right), for infinitesimals 1 ≫ η ≫ ε ≫ εδ, s = ±1, d = toward - p. The ε shift is the
// one curve_intersections applies to its second curve (s = +1 for a point of that curve, -1 for
// a point of the first, as seen from the second); the η step along the point's own curve moves
// it off a touching point, where curve_intersections drops the two crossings the ε shift makes
// (the zero-length piece between them would have the other status). The answer is defined for
// every p. orient_to(i, j, q) is the exact sign of orient(polygon[i], polygon[j], q) for q = p
// and q = toward.
template <class Y, class Orient>
bool inside_shifted(const Points2& polygon, const Y& py, const Y& dy, int s, const Orient& orient_to) {
  const Index n = polygon.rows();
  // Whether height y lies above p.y + η·dy + s·εδ.
  const auto above = [&](double y) {
    if (Y(y) != py) return Y(y) > py;
    if (dy != Y(0)) return dy < Y(0);
    return s < 0;
  };
  bool inside = false;
  for (Index i = 0; i < n; ++i) {
    const Index j = (i + 1) % n;
    const double uy = polygon(i, 1), wy = polygon(j, 1);
    if (above(uy) == above(wy)) continue;  // the edge does not straddle the ray (so uy != wy)
    int o = orient_to(i, j, false);
    // p on the edge's line: orient(u, w, p + η·d) ~ η·orient(u, w, toward), then the ε shift:
    // cross(w - u, s(1, δ)) ~ -s·(wy - uy).
    if (o == 0) o = orient_to(i, j, true);
    if (o == 0) o = -s * detail::sign(wy - uy);
    // The edge meets the ray to the right of p when p is left of an upward edge or right of a
    // downward one.
    if ((wy > uy) == (o > 0)) inside = !inside;
  }
  return inside;
}

// For a double point p (a vertex): CGAL's filtered exact orientation.
bool inside_shifted(const Points2& polygon, const Vec2& p, const Vec2& toward, int s) {
  const Point q(p.x(), p.y()), t(toward.x(), toward.y());
  return inside_shifted(polygon, p.y(), toward.y() - p.y(), s, [&](Index i, Index j, bool to) {
    return detail::orient(detail::point_at(polygon, i), detail::point_at(polygon, j), to ? t : q);
  });
}

// For the exact midpoint of the double points a and b, stepping toward b (rare: see
// first_piece_inside below).
bool inside_shifted_midpoint(const Points2& polygon, const Vec2& a, const Vec2& b, int s) {
  using Q = CGAL::Exact_rational;
  const Q mx = (Q(a.x()) + Q(b.x())) / 2, my = (Q(a.y()) + Q(b.y())) / 2;
  const Point t(b.x(), b.y());
  return inside_shifted(polygon, my, Q(Q(b.y()) - my), s, [&](Index i, Index j, bool to) {
    if (to) return detail::orient(detail::point_at(polygon, i), detail::point_at(polygon, j), t);
    const Q ux(polygon(i, 0)), uy(polygon(i, 1)), wx(polygon(j, 0)), wy(polygon(j, 1));
    return static_cast<int>(CGAL::sign((wx - ux) * (my - uy) - (wy - uy) * (mx - ux)));
  });
}

// One curve's crossings in order along it: by segment, then arc length, then arc length on the
// other curve (segment first, so that the count of crossings before a vertex is exact).
struct Cuts {
  std::vector<Vec2> points;
  std::vector<Index> segment;
  std::vector<double> arc;
};

Cuts cuts_along(const CurveIntersections& x, bool first) {
  const Index k = x.points.rows();
  const IndexVector& seg = first ? x.segments1 : x.segments2;
  const Vector& s = first ? x.arc_lengths1 : x.arc_lengths2;
  const Vector& other = first ? x.arc_lengths2 : x.arc_lengths1;
  std::vector<Index> order(k);
  std::iota(order.begin(), order.end(), Index(0));
  std::stable_sort(order.begin(), order.end(), [&](Index a, Index b) {
    return std::tie(seg(a), s(a), other(a)) < std::tie(seg(b), s(b), other(b));
  });
  Cuts c;
  for (Index r : order) {
    c.points.push_back(x.points.row(r).transpose());
    c.segment.push_back(seg(r));
    c.arc.push_back(s(r));
  }
  return c;
}

// Whether the first piece (from cut 0 to cut 1) of `curve` lies inside `other`, under the shift:
// the curve's points are tested with the shift s (+1 for the shifted second curve, -1 for the
// first curve, as seen from the second). Parity then gives every other piece.
bool first_piece_inside(const Points2& curve, const Vector& arc, const Cuts& c, const Points2& other, int s) {
  const Index n = curve.rows();
  const Index k = static_cast<Index>(c.segment.size());
  // A vertex that is not a crossing: exactly classified, and its piece is exactly known. Vertex
  // i follows the crossings on segments before i; a crossing at vertex i itself is reported at
  // the start (arc length exactly arc(i)) of segment i, and such a vertex is skipped.
  Index before = 0;  // crossings on segments < i
  Index at = 0;      // first cut on segment >= i
  for (Index i = 0; i < n; ++i) {
    while (at < k && c.segment[at] < i) ++at;
    before = at;
    bool on_cut = false;
    for (Index r = at; r < k && c.segment[r] == i && !on_cut; ++r) {
      on_cut = c.arc[r] <= arc(i) || c.points[r] == curve.row(i).transpose();
    }
    if (on_cut || c.points[at > 0 ? at - 1 : k - 1] == curve.row(i).transpose()) continue;
    const bool in = inside_shifted(other, curve.row(i).transpose(), curve.row((i + 1) % n).transpose(), s);
    // Vertex i lies on the piece that starts at cut before - 1 (the last piece, wrapping, when
    // before == 0).
    const Index piece = (before + k - 1) % k;
    return in != (piece % 2 == 1);
  }
  // Every vertex is a crossing, so every piece lies within one segment. Prefer a piece that is a
  // whole segment (both ends exact vertices: the exact midpoint is tested); otherwise the
  // longest piece, by the midpoint of its ends in floating point.
  Index best = 0;
  double longest = -1.0;
  for (Index r = 0; r < k; ++r) {
    const Index next = (r + 1) % k;
    const Vec2 a = c.points[r], b = c.points[next];
    const bool whole = a == curve.row(c.segment[r]).transpose() && b == curve.row((c.segment[r] + 1) % n).transpose();
    if (whole && a != b) return inside_shifted_midpoint(other, a, b, s) != (r % 2 == 1);
    const double length = (b - a).norm();
    if (length > longest) longest = length, best = r;
  }
  const Vec2 mid = 0.5 * (c.points[best] + c.points[(best + 1) % k]);
  return inside_shifted(other, mid, c.points[(best + 1) % k], s) != (best % 2 == 1);
}

// Twice the signed area swept from `origin` by the pieces of `curve` with the given parity
// (pieces inside the other curve).
double inside_pieces(const Points2& curve, const Cuts& c, bool first_inside, const Vec2& origin) {
  const Index n = curve.rows();
  const Index k = static_cast<Index>(c.segment.size());
  double twice = 0.0;
  for (Index r = first_inside ? 0 : 1; r < k; r += 2) {
    const Index next = (r + 1) % k;
    // Vertices between the two cuts: segment[r] + 1 ... segment[next], going forward; the
    // wrapping piece goes all the way round when both cuts are on one segment.
    Index count = c.segment[next] - c.segment[r];
    if (next == 0) count += n;
    Vec2 prev = c.points[r] - origin;
    for (Index step = 1; step <= count; ++step) {
      const Vec2 v = curve.row((c.segment[r] + step) % n).transpose() - origin;
      twice += prev.x() * v.y() - prev.y() * v.x();
      prev = v;
    }
    const Vec2 end = c.points[next] - origin;
    twice += prev.x() * end.y() - prev.y() * end.x();
  }
  return twice;
}

double twice_area(const Points2& p, const Vec2& origin) {
  const Index n = p.rows();
  double twice = 0.0;
  for (Index i = 0; i < n; ++i) {
    const Index j = (i + 1) % n;
    twice += (p(i, 0) - origin.x()) * (p(j, 1) - origin.y()) - (p(j, 0) - origin.x()) * (p(i, 1) - origin.y());
  }
  return twice;
}

Vector arc_positions(const Points2& p) {
  const Index n = p.rows();
  Vector s(n + 1);
  s(0) = 0.0;
  for (Index i = 0; i < n; ++i) s(i + 1) = s(i) + (p.row((i + 1) % n) - p.row(i)).norm();
  return s;
}

}  // namespace

double overlap_area(const Points2Ref& a, const Points2Ref& b) {
  const Points2 pa = counter_clockwise(a, "a");
  const Points2 pb = counter_clockwise(b, "b");
  // Areas relative to a point near both curves, so that far-off coordinates lose few digits.
  const Vec2 origin = 0.5 * (pa.colwise().mean() + pb.colwise().mean()).transpose();

  // Segment indices refer to pa and pb, which have no repeats.
  const CurveIntersections x = curve_intersections(pa, pb, true);
  if (x.points.rows() == 0) {
    // No crossing: one contains the other, or they are apart. The second curve is shifted by
    // ε(1, δ), so a vertex of a is tested shifted by -ε(1, δ), one of b by +ε(1, δ).
    if (inside_shifted(pb, pa.row(0).transpose(), pa.row(1).transpose(), -1)) {
      return 0.5 * twice_area(pa, origin);
    }
    if (inside_shifted(pa, pb.row(0).transpose(), pb.row(1).transpose(), +1)) {
      return 0.5 * twice_area(pb, origin);
    }
    return 0.0;
  }
  // Two closed curves cross an even number of times under the shift.
  if (x.points.rows() % 2 != 0) throw GeometryError("overlap_area: an odd number of crossings");
  const Cuts ca = cuts_along(x, true), cb = cuts_along(x, false);
  const bool a_first = first_piece_inside(pa, arc_positions(pa), ca, pb, -1);
  const bool b_first = first_piece_inside(pb, arc_positions(pb), cb, pa, +1);
  const double twice = inside_pieces(pa, ca, a_first, origin) + inside_pieces(pb, cb, b_first, origin);
  return std::max(0.0, 0.5 * twice);
}

}  // namespace morphomap
