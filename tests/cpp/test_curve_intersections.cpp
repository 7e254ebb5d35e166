// Curve-curve intersections under the symbolic shift of c2. Random polygons against an exact
// brute force are in tests/test_curve_intersections.py.
#include <morphomap/curve_queries.hpp>
#include <morphomap/errors.hpp>

#include "check.hpp"
#include "shapes.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <string>
#include <utility>
#include <vector>

using morphomap::curve_intersections;
using morphomap::CurveIntersections;
using morphomap::Index;
using morphomap::InvalidInput;
using morphomap::Points2;
using morphomap::Vec2;

using morphomap_test::pi;
using morphomap_test::pts;
using morphomap_test::rect;

namespace {

// n points of the ellipse (a cos t, b sin t), t = t0 + 2πi/n, and the points at the angles
// `extra` (in [0, 2π)), all in order of t.
Points2 ellipse(double a, double b, Index n, double t0 = 0, std::vector<double> extra = {}) {
  for (Index i = 0; i < n; ++i) extra.push_back(t0 + 2 * pi * i / n);
  std::sort(extra.begin(), extra.end());
  Points2 p(static_cast<Index>(extra.size()), 2);
  for (Index i = 0; i < p.rows(); ++i) p.row(i) << a * std::cos(extra[i]), b * std::sin(extra[i]);
  return p;
}

bool near(const Points2& p, Index i, double x, double y, double tol) {
  return std::abs(p(i, 0) - x) <= tol && std::abs(p(i, 1) - y) <= tol;
}

// Checks shared by every answer: sizes, order along c1, even count for closed curves.
void check_consistent(const CurveIntersections& r, bool closed) {
  const Index k = r.points.rows();
  CHECK(r.arc_lengths1.size() == k && r.arc_lengths2.size() == k);
  CHECK(r.segments1.size() == k && r.segments2.size() == k);
  for (Index i = 1; i < k; ++i) CHECK(r.arc_lengths1(i - 1) <= r.arc_lengths1(i));
  if (closed) CHECK(k % 2 == 0);
}

// The four crossings of x²/4 + y² = 1 and x² + y²/4 = 1 at (±c, ±c), c = 2/√5, in order along c1
// from (2, 0) counter-clockwise; returns the largest coordinate error.
double ellipse_error(const CurveIntersections& r) {
  const double c = 2 / std::sqrt(5.0);
  const double expected[4][2] = {{c, c}, {-c, c}, {-c, -c}, {c, -c}};
  CHECK(r.points.rows() == 4);
  if (r.points.rows() != 4) return 1;
  double err = 0;
  for (Index i = 0; i < 4; ++i) {
    err = std::max({err, std::abs(r.points(i, 0) - expected[i][0]), std::abs(r.points(i, 1) - expected[i][1])});
  }
  return err;
}

void test_ellipses() {
  const Index n = 20000;
  // Vertices on the crossings (to rounding), so that the answer is limited by rounding only.
  std::vector<double> t1, t2;  // the crossing angles on each ellipse, in [0, 2π)
  for (const auto& [sx, sy] : {std::pair{1, 1}, {-1, 1}, {-1, -1}, {1, -1}}) {
    t1.push_back(std::fmod(std::atan2(2.0 * sy, 1.0 * sx) + 2 * pi, 2 * pi));
    t2.push_back(std::fmod(std::atan2(1.0 * sy, 2.0 * sx) + 2 * pi, 2 * pi));
  }
  const Points2 e1 = ellipse(2, 1, n, 0, t1), e2 = ellipse(1, 2, n, 0, t2);
  const CurveIntersections on = curve_intersections(e1, e2);
  check_consistent(on, true);
  const double err_on = ellipse_error(on);
  CHECK(err_on < 1e-9);

  // Generic vertices: each polyline lies within its chord sagitta σ = κ h² / 8 of its ellipse
  // (κ ≤ 2 for both, h ≤ 2·2π/n the longest chord), so a crossing moves by about σ / sin θ per
  // curve, θ = asin(15/17) the angle between the curves there. Bound: 2σ / sin θ, doubled.
  const Points2 g1 = ellipse(2, 1, n, 0.123), g2 = ellipse(1, 2, n, 0.456);
  const CurveIntersections generic = curve_intersections(g1, g2);
  check_consistent(generic, true);
  const double h = 2 * 2 * pi / n, sigma = 2 * h * h / 8;
  const double bound = 2 * (2 * sigma / (15.0 / 17.0));
  const double err_generic = ellipse_error(generic);
  CHECK(err_generic < bound);
  std::printf(
      "ellipse crossings, %lld points each: error %.3g with vertices on the crossings, "
      "%.3g generic (bound %.3g)\n",
      static_cast<long long>(n), err_on, err_generic, bound);

  // Arc lengths: the point at arc length s1 along c1 is the crossing point.
  for (Index i = 0; i < generic.points.rows(); ++i) {
    const Index k = generic.segments1(i);
    const Vec2 a = g1.row(k), b = g1.row((k + 1) % n);
    double start = 0;
    for (Index j = 0; j < k; ++j) start += (g1.row(j + 1) - g1.row(j)).norm();
    const Vec2 at = a + (generic.arc_lengths1(i) - start) / (b - a).norm() * (b - a);
    CHECK((at - generic.points.row(i).transpose()).norm() < 1e-9);
  }
}

void test_simple_crossings() {
  // Open curves: one crossing, with arc lengths on both.
  const CurveIntersections x = curve_intersections(pts({{0, 0}, {2, 0}}), pts({{1, -1}, {1, 1}}), false);
  CHECK(x.points.rows() == 1);
  CHECK(near(x.points, 0, 1, 0, 0));
  CHECK(x.arc_lengths1(0) == 1 && x.arc_lengths2(0) == 1);
  CHECK(x.segments1(0) == 0 && x.segments2(0) == 0);
  // An end of c2 on c1: the shift (to the right, then up) decides. From above it stays above.
  CHECK(curve_intersections(pts({{0, 0}, {2, 0}}), pts({{1, 0}, {1, 1}}), false).points.rows() == 0);
  const CurveIntersections below = curve_intersections(pts({{0, 0}, {2, 0}}), pts({{1, 0}, {1, -1}}), false);
  CHECK(below.points.rows() == 1 && near(below.points, 0, 1, 0, 0));
  // Squares crossing at two points, with repeated points that must not change the answer.
  const Points2 a = pts({{0, 0}, {0, 0}, {2, 0}, {2, 2}, {0, 2}, {0, 0}});
  const Points2 b = pts({{1, 1}, {3, 1}, {3, 1}, {3, 3}, {1, 3}});
  const CurveIntersections r = curve_intersections(a, b);
  check_consistent(r, true);
  CHECK(r.points.rows() == 2);
  CHECK(near(r.points, 0, 2, 1, 0) && near(r.points, 1, 1, 2, 0));
  CHECK(r.arc_lengths1(0) == 3 && r.arc_lengths1(1) == 5);
  CHECK(r.arc_lengths2(0) == 1 && r.arc_lengths2(1) == 7);
  // Segment indices refer to the given rows: row 1 -> 2 and row 3 -> 4 on c1, 0 and 4 on c2.
  CHECK(r.segments1(0) == 2 && r.segments1(1) == 3);
  CHECK(r.segments2(0) == 0 && r.segments2(1) == 4);
  // Disjoint and nested curves.
  CHECK(curve_intersections(rect(0, 0, 1, 1), rect(2, 2, 3, 3)).points.rows() == 0);
  CHECK(curve_intersections(rect(0, 0, 3, 3), rect(1, 1, 2, 2)).points.rows() == 0);
}

void test_touching() {
  const Points2 square = rect(0, 0, 1, 1);
  // A vertex of c2 on an edge of c1, from outside and from inside: no crossing. Inside on the
  // right edge the shift pushes the vertex out, making two crossings at one point that are
  // neighbours along both curves: dropped.
  for (const Points2& c2 : {pts({{1, 0.5}, {2, 0}, {2, 1}}), pts({{1, 0.5}, {0.5, 0.8}, {0.5, 0.2}}),
                            pts({{0, 0.5}, {-1, 0}, {-1, 1}}), pts({{0, 0.5}, {0.5, 0.2}, {0.5, 0.8}})}) {
    const CurveIntersections r = curve_intersections(square, c2);
    check_consistent(r, true);
    CHECK(r.points.rows() == 0);
    const CurveIntersections swapped = curve_intersections(c2, square);
    CHECK(swapped.points.rows() == 0);  // now a vertex of c1 on an edge of c2
  }
  // Vertex on vertex, touching from outside at a corner.
  CHECK(curve_intersections(square, rect(1, 1, 2, 2)).points.rows() == 0);
  CHECK(curve_intersections(square, pts({{1, 1}, {2, 1.5}, {1.5, 2}})).points.rows() == 0);
  // A vertex of c2 on c1 where c2 does pass through: one crossing each time, at the vertex.
  const CurveIntersections through = curve_intersections(square, pts({{1, 0.5}, {0.5, 0.8}, {2, 0.9}}));
  check_consistent(through, true);
  CHECK(through.points.rows() == 2 && near(through.points, 0, 1, 0.5, 0));

  // A circle tangent inside another at (2, 0), both with a vertex there; the inner one is
  // coarser so that its polyline stays inside the outer one's away from the tangent point.
  Points2 outer = ellipse(2, 2, 400), inner = ellipse(1, 1, 100);
  inner.col(0).array() += 1;
  CHECK(inner(0, 0) == 2 && inner(0, 1) == 0 && outer(0, 0) == 2 && outer(0, 1) == 0);
  for (const auto& [c1, c2] : {std::pair{outer, inner}, std::pair{inner, outer}}) {
    const CurveIntersections r = curve_intersections(c1, c2);
    check_consistent(r, true);
    CHECK(r.points.rows() == 0);
  }
  // Tangent outside, touching at (2, 0) from the right.
  Points2 beside = ellipse(1, 1, 100);
  beside.col(0) = 3 - beside.col(0).array();
  CHECK(beside(0, 0) == 2 && beside(0, 1) == 0);
  for (const auto& [c1, c2] : {std::pair{outer, beside}, std::pair{beside, outer}}) {
    const CurveIntersections r = curve_intersections(c1, c2);
    check_consistent(r, true);
    CHECK(r.points.rows() == 0);
  }
}

void test_overlaps() {
  const Points2 square = rect(0, 0, 1, 1);
  // Squares sharing part of an edge, side by side and nested. The shift moves c2 to the right:
  // where that takes the shared piece of c2 into the other square, c2 enters and leaves at the
  // ends of the shared piece (two crossings), otherwise it stays clear (none).
  struct Case {
    Points2 c2;
    Index count;
  };
  const Case cases[] = {
      {rect(1, 0.25, 2, 0.75), 0},                 // beside, on the right
      {rect(-1, 0.25, 0, 0.75), 2},                // beside, on the left: shifted into the square
      {rect(0, 0.25, 0.5, 0.75), 0},               // nested on the left edge: shifted inwards
      {rect(0.5, 0.25, 1, 0.75), 2},               // nested on the right edge: shifted out
      {rect(0.25, 1, 0.75, 2), 0},                 // beside, on top: shifted along the edge and up
      {rect(0.25, 0, 0.75, 0.5), 0},               // nested on the bottom edge
      {rect(0.25, -1, 0.75, 0), 2},                // beside, below: shifted up into the square
      {rect(1, 0, 2, 1), 0},                       // a whole edge shared
      {rect(0.5, 0, 1.5, 1), 2},                   // overlapping halves: two proper crossings
      {square, 2},                                 // identical: the shifted copy crosses at two corners
      {pts({{0, 0}, {0, 1}, {1, 1}, {1, 0}}), 2},  // identical, the other way round
  };
  for (const Case& c : cases) {
    const CurveIntersections r = curve_intersections(square, c.c2);
    check_consistent(r, true);
    CHECK(r.points.rows() == c.count);
    const CurveIntersections swapped = curve_intersections(c.c2, square);
    check_consistent(swapped, true);
  }
  const CurveIntersections left = curve_intersections(square, rect(-1, 0.25, 0, 0.75));
  CHECK(near(left.points, 0, 0, 0.75, 0) && near(left.points, 1, 0, 0.25, 0));
  const CurveIntersections same = curve_intersections(square, square);
  CHECK(near(same.points, 0, 1, 0, 0) && near(same.points, 1, 0, 1, 0));

  // Open curves running along each other from (1, 0) to (2, 0). The shift lifts c2 above c1
  // there, so c2 arriving from below crosses at (1, 0), and c2 leaving below crosses at (2, 0).
  const Points2 c1 = pts({{0, 0}, {1, 0}, {2, 0}, {3, 1}});
  const CurveIntersections below = curve_intersections(c1, pts({{0, -1}, {1, 0}, {2, 0}, {3, -1}}), false);
  CHECK(below.points.rows() == 2 && near(below.points, 0, 1, 0, 0) && near(below.points, 1, 2, 0, 0));
  const CurveIntersections up = curve_intersections(c1, pts({{0, -1}, {1, 0}, {2, 0}, {3, 2}}), false);
  CHECK(up.points.rows() == 1 && near(up.points, 0, 1, 0, 0));
  const CurveIntersections down = curve_intersections(c1, pts({{0, 1}, {1, 0}, {2, 0}, {3, -1}}), false);
  CHECK(down.points.rows() == 1 && near(down.points, 0, 2, 0, 0));
  CHECK(curve_intersections(c1, pts({{0, 1}, {1, 0}, {2, 0}, {3, 2}}), false).points.rows() == 0);
}

void test_validation() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Points2 ok = rect(0, 0, 1, 1);
  const auto message = [](auto f) -> std::string {
    try {
      f();
    } catch (const InvalidInput& e) {
      return e.what();
    }
    return "";
  };
  CHECK(message([&] { curve_intersections(pts({{0, 0}, {nan, 0}, {1, 1}}), ok); }).rfind("c1", 0) == 0);
  CHECK(message([&] { curve_intersections(ok, pts({{0, 0}, {1, 0}})); }).rfind("c2", 0) == 0);
  CHECK(message([&] { curve_intersections(ok, pts({{0, 0}, {1, 0}, {1, 0}, {0, 0}})); }).rfind("c2", 0) == 0);
  CHECK_THROWS(curve_intersections(pts({{0, 0}}), ok, false), InvalidInput);
}

}  // namespace

int main() {
  test_ellipses();
  test_simple_crossings();
  test_touching();
  test_overlaps();
  test_validation();
  TEST_MAIN_END();
}
