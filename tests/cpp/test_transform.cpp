// Overlap area of two closed curves (against Sutherland–Hodgman clipping by a convex polygon,
// which is exact for any simple subject polygon) and the aligning similarity of Appendix A.
#include <morphomap/errors.hpp>
#include <morphomap/transform.hpp>

#include "check.hpp"
#include "shapes.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

using morphomap::align_curves;
using morphomap::Index;
using morphomap::InvalidInput;
using morphomap::overlap_area;
using morphomap::Points2;
using morphomap::Similarity2;
using morphomap::Vec2;

using morphomap_test::pi;
using morphomap_test::pts;
using morphomap_test::rect;

namespace {

Points2 reversed(const Points2& p) { return p.colwise().reverse(); }

Points2 shifted(Points2 p, double dx, double dy) {
  p.col(0).array() += dx;
  p.col(1).array() += dy;
  return p;
}

// Counter-clockwise regular polygon.
Points2 regular(Index n, double radius, double cx = 0, double cy = 0, double phase = 0) {
  Points2 p(n, 2);
  for (Index i = 0; i < n; ++i) {
    const double t = phase + 2 * pi * i / n;
    p.row(i) << cx + radius * std::cos(t), cy + radius * std::sin(t);
  }
  return p;
}

// A non-convex star-shaped blob r(t), counter-clockwise.
Points2 star(Index n, double cx = 0, double cy = 0) {
  Points2 p(n, 2);
  for (Index i = 0; i < n; ++i) {
    const double t = 2 * pi * i / n;
    const double r = 1.0 + 0.3 * std::sin(5 * t) + 0.1 * std::cos(11 * t);
    p.row(i) << cx + r * std::cos(t), cy + r * std::sin(t);
  }
  return p;
}

// A kidney-like blob without any rotational or mirror symmetry.
Points2 kidney(Index n) {
  Points2 p(n, 2);
  for (Index i = 0; i < n; ++i) {
    const double t = 2 * pi * i / n;
    const double r = 1.0 + 0.25 * std::cos(t) - 0.3 * std::cos(2 * t - 0.4) + 0.08 * std::sin(3 * t);
    p.row(i) << 1.2 * r * std::cos(t), r * std::sin(t);
  }
  return p;
}

double shoelace(const std::vector<Vec2>& p) {
  double twice = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec2& a = p[i];
    const Vec2& b = p[(i + 1) % p.size()];
    twice += a.x() * b.y() - b.x() * a.y();
  }
  return 0.5 * twice;
}

// Area of the subject polygon clipped by the convex counter-clockwise polygon `clip`.
double clipped_area(const Points2& subject, const Points2& clip) {
  std::vector<Vec2> out;
  for (Index i = 0; i < subject.rows(); ++i) out.push_back(subject.row(i).transpose());
  const Index m = clip.rows();
  for (Index e = 0; e < m && !out.empty(); ++e) {
    const Vec2 a = clip.row(e).transpose(), b = clip.row((e + 1) % m).transpose();
    const auto side = [&](const Vec2& p) {
      return (b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x());
    };
    std::vector<Vec2> in;
    in.swap(out);
    for (std::size_t i = 0; i < in.size(); ++i) {
      const Vec2& p = in[i];
      const Vec2& q = in[(i + 1) % in.size()];
      const double sp = side(p), sq = side(q);
      if (sp >= 0) out.push_back(p);
      if ((sp >= 0) != (sq >= 0)) out.push_back(p + sp / (sp - sq) * (q - p));
    }
  }
  return out.size() < 3 ? 0.0 : std::abs(shoelace(out));
}

double area_of(const Points2& p) {
  std::vector<Vec2> v;
  for (Index i = 0; i < p.rows(); ++i) v.push_back(p.row(i).transpose());
  return std::abs(shoelace(v));
}

// Both argument orders and all four orientations.
void check_area(const Points2& a, const Points2& b, double expected, double tol) {
  for (const Points2& x : {a, reversed(a)}) {
    for (const Points2& y : {b, reversed(b)}) {
      CHECK_NEAR(overlap_area(x, y), expected, tol);
      CHECK_NEAR(overlap_area(y, x), expected, tol);
    }
  }
}

void test_squares() {
  const Points2 unit = rect(0, 0, 1, 1);
  check_area(unit, shifted(unit, 0.3, 0.4), 0.7 * 0.6, 1e-15);
  check_area(unit, shifted(unit, -0.3, 0.4), 0.7 * 0.6, 1e-15);
  // Touching and shared stretches: the exact answer, whatever the shift of the second curve.
  check_area(unit, unit, 1.0, 1e-15);
  check_area(unit, shifted(unit, 0.5, 0), 0.5, 1e-15);
  check_area(unit, shifted(unit, 0, -0.5), 0.5, 1e-15);
  check_area(unit, shifted(unit, 1, 0), 0.0, 0);
  check_area(unit, shifted(unit, 0, 1), 0.0, 0);
  check_area(unit, shifted(unit, 1, 1), 0.0, 0);
  check_area(unit, shifted(unit, -1, -1), 0.0, 0);
  check_area(unit, rect(0, 0, 1, 2), 1.0, 1e-15);
  check_area(unit, rect(0, 0, 0.5, 0.5), 0.25, 1e-15);
  check_area(unit, rect(0.5, 0.5, 1, 1), 0.25, 1e-15);
  check_area(unit, rect(-1, 0.25, 2, 0.75), 0.5, 1e-15);
  check_area(unit, rect(0.25, -1, 0.75, 2), 0.5, 1e-15);
  // A closing repeat and repeated points are dropped.
  Points2 closed_again(5, 2);
  closed_again << unit, unit.row(0);
  CHECK_NEAR(overlap_area(closed_again, shifted(unit, 0.3, 0.4)), 0.42, 1e-15);
  const Points2 repeats = pts({{0, 0}, {0, 0}, {1, 0}, {1, 1}, {1, 1}, {0, 1}});
  CHECK_NEAR(overlap_area(repeats, shifted(repeats, 0.3, 0.4)), 0.42, 1e-15);
  // The diamond through the midpoints of the edges, and the one through the corners (contains
  // the square, touching it at its corners).
  const Points2 inner = pts({{0.5, 0}, {1, 0.5}, {0.5, 1}, {0, 0.5}});
  check_area(unit, inner, 0.5, 1e-15);
  const Points2 outer = pts({{0.5, -0.5}, {1.5, 0.5}, {0.5, 1.5}, {-0.5, 0.5}});
  check_area(unit, outer, 1.0, 1e-15);
}

// Every corner of the square is a crossing: the pieces are whole edges or parts of one edge.
void test_all_vertices_cross() {
  const Points2 unit = rect(0, 0, 1, 1);
  const Points2 dents = pts({{0, 0}, {0.5, 0.3}, {1, 0}, {1.3, 0.5}, {1, 1}, {0.5, 0.7}, {0, 1}, {-0.3, 0.5}});
  check_area(unit, dents, 0.7, 1e-15);
  CHECK_NEAR(clipped_area(dents, unit), 0.7, 1e-15);
  // Dents that also cross the edges inside them.
  const Points2 deep =
      pts({{0, 0}, {0.5, 0.3}, {0.8, -0.3}, {1, 0}, {1.3, 0.5}, {1, 1}, {0.5, 0.7}, {0.2, 1.3}, {0, 1}, {-0.3, 0.5}});
  check_area(unit, deep, clipped_area(deep, unit), 1e-15);
}

void test_circle_with_itself() {
  for (Index n : {3, 7, 100, 1000}) {
    const Points2 c = regular(n, 1.0, 0.25, -0.5, 0.1);
    check_area(c, c, area_of(c), 1e-12);
  }
  const Points2 s = star(700);
  check_area(s, s, area_of(s), 1e-12);
}

void test_regular_polygons() {
  std::mt19937 rng(20141);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  double worst = 0;
  for (int trial = 0; trial < 200; ++trial) {
    const Index n = 3 + trial % 40, m = 3 + (trial * 7) % 60;
    const Points2 a = regular(n, 1.0 + 0.5 * u(rng), u(rng), u(rng), u(rng));
    const Points2 b = regular(m, 1.0 + 0.5 * u(rng), u(rng), u(rng), u(rng));
    const double expected = clipped_area(a, b);
    const double got = overlap_area(a, b);
    worst = std::max(worst, std::abs(got - expected));
    CHECK_NEAR(got, expected, 1e-12);
    CHECK_NEAR(overlap_area(b, reversed(a)), expected, 1e-12);
  }
  std::printf("regular polygons vs Sutherland-Hodgman: max error %.2e\n", worst);
  // Disjoint and nested.
  const Points2 a = regular(50, 1.0), far = regular(30, 0.5, 3, 0), inside = regular(30, 0.5, 0.2, 0.1);
  check_area(a, far, 0.0, 0);
  check_area(a, inside, area_of(inside), 1e-14);
}

void test_star_and_circle() {
  const Points2 s = star(2000, 0.1, -0.05);
  double worst = 0;
  for (double shift : {0.0, 0.3, 0.7, 1.4}) {
    const Points2 circle = regular(1500, 1.05, shift, 0.2);
    // The reference clips the non-convex star by the convex circle polygon.
    const double expected = clipped_area(s, circle);
    const double got = overlap_area(s, circle);
    worst = std::max(worst, std::abs(got - expected));
    check_area(s, circle, expected, 1e-12);
  }
  std::printf("star vs circle: max error %.2e\n", worst);
}

void test_timing() {
  for (Index n : {1000, 10000}) {
    const Points2 a = star(n);
    Similarity2 t;
    t.angle = 0.3, t.translation = Vec2(0.05, -0.02), t.scale = 1.02;
    const Points2 b = t.apply(star(n + 17));
    const int calls = n > 5000 ? 50 : 200;
    double sum = 0;
    const auto start = std::chrono::steady_clock::now();
    for (int k = 0; k < calls; ++k) sum += overlap_area(a, b);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    CHECK(sum > 0);
    std::printf("overlap_area, %lld-point curves: %.3f ms per call\n", static_cast<long long>(n),
                1e3 * seconds / calls);
  }
}

double max_distance(const Points2& a, const Points2& b) { return (a - b).rowwise().norm().maxCoeff(); }

void test_similarity() {
  Similarity2 t;
  t.centre = Vec2(0.3, -1.2);
  t.scale = 1.7;
  t.angle = 2.1;
  t.translation = Vec2(-4, 0.5);
  const Points2 p = star(50, 3, 4);
  CHECK(max_distance(t.apply_inverse(t.apply(p)), p) < 1e-13);
  CHECK(max_distance(t.apply(t.apply_inverse(p)), p) < 1e-13);
  // The centre goes to centre + translation; distances scale.
  const Points2 c = t.apply(pts({{0.3, -1.2}, {1.3, -1.2}}));
  CHECK_NEAR(c(0, 0), -3.7, 1e-15);
  CHECK_NEAR(c(0, 1), -0.7, 1e-15);
  CHECK_NEAR((c.row(1) - c.row(0)).norm(), 1.7, 1e-14);
  CHECK_NEAR(std::atan2(c(1, 1) - c(0, 1), c(1, 0) - c(0, 0)), 2.1, 1e-14);
  Similarity2 singular;
  singular.scale = 0;
  CHECK_THROWS(singular.apply_inverse(p), InvalidInput);
}

void test_align_closed() {
  const Points2 c1 = kidney(1000);
  const double size1 = std::sqrt(area_of(c1));
  Similarity2 truth;
  truth.centre = Vec2(0.1, 0.05);
  truth.scale = 1.3;
  truth.angle = 23.7 * pi / 180;
  truth.translation = Vec2(0.16, -0.12) * size1;  // 0.2 size
  const Points2 c2 = truth.apply(c1);
  const double size2 = std::sqrt(area_of(c2));
  for (const Points2& target : {c2, reversed(c2)}) {
    const auto start = std::chrono::steady_clock::now();
    const Similarity2 found = align_curves(c1, target);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double error = max_distance(found.apply(c1), c2) / size2;
    std::printf(
        "align_curves (1000 points, 23.7 degrees, 1.3x, shift 0.2 size): error %.2e of the "
        "size, scale %.8f, angle %.6f degrees, %.2f s\n",
        error, found.scale, found.angle * 180 / pi, seconds);
    CHECK(error < 1e-3);
    CHECK_NEAR(found.scale, 1.3, 1e-12);
  }
  // 10^4 points, timed.
  {
    const Points2 big1 = kidney(10000), big2 = truth.apply(kidney(10000));
    const auto start = std::chrono::steady_clock::now();
    const Similarity2 found = align_curves(big1, big2);
    const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double error = max_distance(found.apply(big1), big2) / size2;
    std::printf("align_curves (10000 points): error %.2e of the size, %.2f s\n", error, seconds);
    CHECK(error < 1e-3);
  }
  // Already aligned: the identity.
  const Similarity2 same = align_curves(c2, c2);
  CHECK(max_distance(same.apply(c2), c2) / size2 < 1e-5);
}

// C2 with a bump, so that the best overlap is not centroid on centroid: the answer is a local
// maximum, better than the start and than every step of the final sizes around it.
void test_align_local_maximum() {
  const Points2 c1 = kidney(800);
  Similarity2 truth;
  truth.scale = 0.8;
  truth.angle = -0.3;
  truth.translation = Vec2(0.1, 0.15);
  Points2 c2 = truth.apply(c1);
  for (Index i = 0; i < c2.rows(); ++i) {
    const double t = 2 * pi * i / c2.rows();
    const double bump = 0.35 * std::exp(-std::pow((t - 1.0) / 0.3, 2));
    c2.row(i) *= 1 + bump;
  }
  const double area2 = area_of(c2), size2 = std::sqrt(area2);
  const Similarity2 found = align_curves(c1, c2, true, 1e-7);
  const double best = overlap_area(found.apply(c1), c2);
  Similarity2 start = found;
  start.angle = 0;
  start.translation = Vec2::Zero();
  CHECK(best > overlap_area(start.apply(c1), c2));
  for (double step : {1e-2, 1e-3, 1e-4}) {
    for (int k = 0; k < 10; ++k) {
      Similarity2 moved = found;
      if (k < 8) {
        moved.translation += step * size2 * Vec2(std::cos(k * pi / 4), std::sin(k * pi / 4));
      } else {
        moved.angle += (k == 8 ? 1 : -1) * step;
      }
      CHECK(overlap_area(moved.apply(c1), c2) <= best + 1e-12 * area2);
    }
  }
  std::printf("align_curves with a bump: overlap %.6f of area(C2)\n", best / area2);
}

void test_align_open() {
  Points2 c1(40, 2), c2(25, 2);
  for (Index i = 0; i < 40; ++i) c1.row(i) << i * 0.1, std::sin(i * 0.2);
  for (Index i = 0; i < 25; ++i) c2.row(i) << 5 + std::cos(i * 0.1), -2 + i * 0.3;
  const Similarity2 t = align_curves(c1, c2, false);
  const Points2 moved = t.apply(c1);
  CHECK((moved.row(0) - c2.row(0)).norm() < 1e-12);
  CHECK((moved.row(39) - c2.row(24)).norm() < 1e-12);
  // Tolerance is not used for open curves, but still checked.
  CHECK_THROWS(align_curves(c1, c2, false, 0.0), InvalidInput);
}

void test_invalid() {
  const Points2 unit = rect(0, 0, 1, 1);
  Points2 bad = unit;
  bad(2, 1) = std::numeric_limits<double>::quiet_NaN();
  CHECK_THROWS(overlap_area(bad, unit), InvalidInput);
  CHECK_THROWS(overlap_area(unit, bad), InvalidInput);
  CHECK_THROWS(overlap_area(pts({{0, 0}, {1, 0}}), unit), InvalidInput);
  CHECK_THROWS(overlap_area(unit, pts({{0, 0}, {1, 0}, {2, 0}})), InvalidInput);  // zero area
  CHECK_THROWS(align_curves(bad, unit), InvalidInput);
  CHECK_THROWS(align_curves(unit, pts({{0, 0}, {1, 1}, {2, 2}})), InvalidInput);
  CHECK_THROWS(align_curves(pts({{0, 0}, {1, 1}, {1, 0}, {0, 1}}), unit), InvalidInput);  // bow tie
  CHECK_THROWS(align_curves(unit, unit, true, -1.0), InvalidInput);
  CHECK_THROWS(align_curves(unit, unit, true, std::numeric_limits<double>::quiet_NaN()), InvalidInput);
  CHECK_THROWS(align_curves(pts({{0, 0}, {1, 1}, {0, 0}}), pts({{0, 0}, {1, 0}}), false), InvalidInput);
  CHECK_THROWS(align_curves(pts({{0, 0}, {1, 0}}), pts({{0, 0}, {1, 1}, {0, 0}}), false), InvalidInput);
  CHECK_THROWS(align_curves(pts({{0, 0}}), pts({{0, 0}, {1, 0}}), false), InvalidInput);
  try {
    overlap_area(unit, bad);
  } catch (const InvalidInput& e) {
    CHECK(std::string(e.what()).rfind("b:", 0) == 0);
  }
}

}  // namespace

int main() {
  test_squares();
  test_all_vertices_cross();
  test_circle_with_itself();
  test_regular_polygons();
  test_star_and_circle();
  test_timing();
  test_similarity();
  test_align_closed();
  test_align_local_maximum();
  test_align_open();
  test_invalid();
  TEST_MAIN_END();
}
