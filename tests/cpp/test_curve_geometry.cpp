// Arc length, area, orientation, normals and self-intersection of one curve.
#include <morphomap/curve_geometry.hpp>
#include <morphomap/errors.hpp>

#include "check.hpp"
#include "shapes.hpp"

#include <cmath>
#include <limits>
#include <random>
#include <string>

using morphomap::Index;
using morphomap::InvalidInput;
using morphomap::Points2;
using morphomap::Vec2;
using morphomap::Vector;
namespace mm = morphomap;

using morphomap_test::pi;
using morphomap_test::pts;

namespace {

Points2 reversed(const Points2& p) { return p.colwise().reverse(); }

// Points on the unit circle at the given angles.
Points2 on_circle(const std::vector<double>& angles) {
  Points2 p(static_cast<Index>(angles.size()), 2);
  for (std::size_t i = 0; i < angles.size(); ++i) p.row(i) << std::cos(angles[i]), std::sin(angles[i]);
  return p;
}

template <class F>
std::string invalid_message(F f) {
  try {
    f();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "";
}

bool starts_with(const std::string& s, const std::string& prefix) { return s.rfind(prefix, 0) == 0; }

void test_lengths_and_area() {
  const Points2 square = pts({{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  const Vector s = mm::arc_lengths(square);
  CHECK(s.size() == 4);
  CHECK(s(0) == 0 && s(1) == 1 && s(2) == 2 && s(3) == 3);
  CHECK(mm::perimeter(square) == 4);
  CHECK(mm::perimeter(square, false) == 3);
  CHECK(mm::arc_lengths(square, false)(3) == 3);
  // A closed curve that repeats its first point: one value per row, the last is the perimeter.
  const Points2 repeated = pts({{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}});
  CHECK(mm::arc_lengths(repeated).size() == 5);
  CHECK(mm::arc_lengths(repeated)(4) == 4);
  CHECK(mm::perimeter(repeated) == 4);
  CHECK_NEAR(mm::perimeter(pts({{0, 0}, {3, 4}}), false), 5, 0);

  CHECK(mm::signed_area(square) == 1);
  CHECK(mm::signed_area(reversed(square)) == -1);
  CHECK(mm::signed_area(repeated) == 1);
  CHECK(mm::orientation(square) == 1);
  CHECK(mm::orientation(reversed(square)) == -1);
  // A figure eight with equal lobes and a flat polygon enclose zero area: no orientation.
  const Points2 eight = pts({{0, 0}, {1, 1}, {1, 0}, {0, 1}});
  CHECK(mm::signed_area(eight) == 0);
  CHECK(starts_with(invalid_message([&] { mm::orientation(eight); }), "points"));
  CHECK_THROWS(mm::orientation(pts({{0, 0}, {1, 0}, {2, 0}})), InvalidInput);
  CHECK_THROWS(mm::normals(eight), InvalidInput);
  // Far from the origin the plain shoelace sum in doubles loses the answer; the sign is exact.
  const double far = 1e16;
  const Points2 tiny = pts({{far, far}, {far + 2, far}, {far, far + 2}});
  CHECK(mm::orientation(tiny) == 1);
  CHECK(mm::orientation(reversed(tiny)) == -1);
  CHECK(mm::signed_area(tiny) == 2);

  const double nan = std::numeric_limits<double>::quiet_NaN();
  CHECK(starts_with(invalid_message([&] { mm::perimeter(pts({{0, 0}, {nan, 1}, {1, 1}})); }), "points"));
  CHECK(starts_with(invalid_message([&] { mm::arc_lengths(pts({{0, 0}, {1, 1}})); }), "points"));
  CHECK(mm::arc_lengths(pts({{0, 0}, {1, 1}}), false).size() == 2);
  CHECK_THROWS(mm::signed_area(pts({{1, 1}, {1, 1}, {1, 1}})), InvalidInput);
}

void test_normals_circle() {
  // Symmetric vertices: the normal is exactly radial (up to rounding), outward either way round.
  const Index n = 100;
  std::vector<double> angles(n);
  for (Index i = 0; i < n; ++i) angles[i] = 2 * pi * i / n;
  const Points2 ccw = on_circle(angles);
  for (const Points2& c : {ccw, Points2(reversed(ccw))}) {
    const Points2 nrm = mm::normals(c);
    CHECK(nrm.rows() == n);
    for (Index i = 0; i < n; ++i) CHECK_NEAR((nrm.row(i) - c.row(i)).norm(), 0, 1e-14);
  }
  // Uneven spacing: the normal at angle θ with neighbours θ - a and θ + b points at θ + (b - a)/4
  // (the mean of the two chord normals): with spacing 2π/100 · (1 ± 2%), |b - a|/4 < 1e-3.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.01, 0.01);
  for (Index i = 0; i < n; ++i) angles[i] = 2 * pi * (i + jitter(rng)) / n;
  const Points2 uneven = on_circle(angles);
  const Points2 nrm = mm::normals(uneven);
  const Points2 nrm_cw = mm::normals(reversed(uneven));
  for (Index i = 0; i < n; ++i) {
    const double before = angles[(i + n - 1) % n] - (i == 0 ? 2 * pi : 0);
    const double after = angles[(i + 1) % n] + (i == n - 1 ? 2 * pi : 0);
    const double expected = angles[i] + ((after - angles[i]) - (angles[i] - before)) / 4;
    CHECK_NEAR(nrm(i, 0), std::cos(expected), 1e-13);
    CHECK_NEAR(nrm(i, 1), std::sin(expected), 1e-13);
    CHECK_NEAR(nrm.row(i).norm(), 1, 1e-15);
    CHECK((nrm.row(i) - uneven.row(i)).norm() < 1e-3);
    CHECK((nrm_cw.row(n - 1 - i) - nrm.row(i)).norm() < 1e-15);
  }
}

void test_normals_polygons() {
  const double h = std::sqrt(0.5);
  // Square with edge midpoints, both orientations: outward diagonals at corners, axes on edges.
  const Points2 square = pts({{0, 0}, {1, 0}, {2, 0}, {2, 1}, {2, 2}, {1, 2}, {0, 2}, {0, 1}});
  const Points2 expected = pts({{-h, -h}, {0, -1}, {h, -h}, {1, 0}, {h, h}, {0, 1}, {-h, h}, {-1, 0}});
  CHECK((mm::normals(square) - expected).norm() < 1e-15);
  CHECK((mm::normals(reversed(square)) - reversed(expected)).norm() < 1e-15);
  // Repeated points get the normal of their distinct neighbours; a closing repeat is point 0.
  const Points2 repeats = pts({{0, 0}, {1, 0}, {1, 0}, {2, 0}, {2, 2}, {2, 2}, {0, 2}, {0, 0}});
  const Points2 nr = mm::normals(repeats);
  CHECK(nr.rows() == 8);
  CHECK((nr.row(1) - Vec2(0, -1).transpose()).norm() < 1e-15);
  CHECK((nr.row(2) - Vec2(0, -1).transpose()).norm() < 1e-15);
  CHECK((nr.row(4) - Vec2(h, h).transpose()).norm() < 1e-15);
  CHECK((nr.row(5) - Vec2(h, h).transpose()).norm() < 1e-15);
  CHECK((nr.row(7) - nr.row(0)).norm() == 0);
  CHECK((nr.row(0) - Vec2(-h, -h).transpose()).norm() < 1e-15);

  // Open curves: to the right of the direction of travel, one segment at the ends.
  const Points2 line = pts({{0, 0}, {1, 0}, {1, 0}, {2, 0}});
  const Points2 nl = mm::normals(line, false);
  for (Index i = 0; i < 4; ++i) CHECK((nl.row(i) - Vec2(0, -1).transpose()).norm() == 0);
  const Points2 corner = mm::normals(pts({{0, 0}, {1, 0}, {1, 1}}), false);
  CHECK((corner.row(0) - Vec2(0, -1).transpose()).norm() == 0);
  CHECK((corner.row(1) - Vec2(h, -h).transpose()).norm() < 1e-15);
  CHECK((corner.row(2) - Vec2(1, 0).transpose()).norm() == 0);
  // Turning straight back: the normal points along the incoming segment.
  const Points2 spike = mm::normals(pts({{0, 0}, {2, 0}, {1, 0}}), false);
  CHECK((spike.row(1) - Vec2(1, 0).transpose()).norm() == 0);
  CHECK_THROWS(mm::normals(pts({{0, 0}, {0, 0}}), false), InvalidInput);
}

// A star-shaped polygon with random radii: simple by construction.
Points2 random_star(Index n, std::mt19937& rng) {
  std::uniform_real_distribution<double> radius(0.5, 1.5);
  Points2 p(n, 2);
  for (Index i = 0; i < n; ++i) {
    const double r = radius(rng), t = 2 * pi * i / n;
    p.row(i) << r * std::cos(t), r * std::sin(t);
  }
  return p;
}

void test_self_intersection() {
  const Points2 square = pts({{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  CHECK(!mm::is_self_intersecting(square));
  CHECK(!mm::is_self_intersecting(square, false));
  CHECK(mm::is_self_intersecting(pts({{0, 0}, {1, 1}, {1, 0}, {0, 1}})));  // bow tie
  // A vertex touching a non-adjacent edge.
  CHECK(mm::is_self_intersecting(pts({{0, 0}, {2, 0}, {2, 2}, {1, 0}, {0, 2}})));
  // A vertex visited twice.
  CHECK(mm::is_self_intersecting(pts({{0, 0}, {1, 0}, {1, 1}, {0, 0}, {-1, 0}, {-1, -1}})));
  // Folding back onto the previous segment, also across the closing point of a closed curve.
  CHECK(mm::is_self_intersecting(pts({{0, 0}, {2, 0}, {1, 0}}), false));
  CHECK(mm::is_self_intersecting(pts({{0, 0}, {1, 0}, {2, 0}})));
  CHECK(mm::is_self_intersecting(pts({{1, 0}, {1, 1}, {0, 1}, {0, 0}, {2, 0}})));
  CHECK(!mm::is_self_intersecting(pts({{0, 0}, {1, 0}, {2, 0}}), false));  // straight on
  // Repeated points are dropped, including a closing repeat.
  CHECK(!mm::is_self_intersecting(pts({{0, 0}, {1, 0}, {1, 0}, {1, 1}, {0, 1}, {0, 0}})));
  // An open curve ending on its start touches itself.
  CHECK(mm::is_self_intersecting(pts({{0, 0}, {1, 0}, {1, 1}, {0, 0}}), false));
  // Near-degenerate: a vertex within one unit in the last place of the line through an edge.
  // In doubles 3 * y - 1 rounds to 0 for both y below, yet only the first touches the edge.
  const double y = 1.0 / 3.0, above = std::nextafter(y, 1.0);  // y < 1/3 < above
  CHECK(mm::is_self_intersecting(pts({{0, 0}, {3, 1}, {3, 3}, {1, y}, {0, 3}}), false));
  CHECK(!mm::is_self_intersecting(pts({{0, 0}, {3, 1}, {3, 3}, {1, above}, {0, 3}}), false));
  CHECK(!mm::is_self_intersecting(pts({{0, 0}, {4, 0}, {4, 4}, {0, 4}, {0.1, 1}, {3.9, 1}, {0.1, 3}}), false));
  CHECK(mm::is_self_intersecting(pts({{0, 0}, {2, 1}, {2, 2}, {1, 0.5}, {0, 2}}), false));

  std::mt19937 rng(3);
  for (int trial = 0; trial < 5; ++trial) {
    Points2 star = random_star(5000, rng);
    CHECK(!mm::is_self_intersecting(star));
    star.row(2500) = star.row(10);  // a vertex visited twice
    CHECK(mm::is_self_intersecting(star));
    star.row(2500) *= 3;  // a spike across the polygon
    CHECK(mm::is_self_intersecting(star));
  }
  CHECK(starts_with(invalid_message([&] { mm::is_self_intersecting(pts({{0, 0}, {1, 0}})); }), "points"));
}

}  // namespace

int main() {
  test_lengths_and_area();
  test_normals_circle();
  test_normals_polygons();
  test_self_intersection();
  TEST_MAIN_END();
}
