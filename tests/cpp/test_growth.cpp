// Growth kinematics against closed forms: a uniform scaling (isotropic, no direction), a triangle
// whose plane holds the axis of a stretch (stretches and directions known), a square's sides.
#include <morphomap/errors.hpp>
#include <morphomap/growth.hpp>

#include "check.hpp"
#include "surfaces.hpp"

#include <cmath>

using morphomap::curve_growth;
using morphomap::Faces;
using morphomap::Index;
using morphomap::InvalidInput;
using morphomap::Points2;
using morphomap::Points3;
using morphomap::Segments;
using morphomap::surface_growth;

namespace {

void test_scaling() {
  const auto s = morphomap_test::icosphere(2);
  const auto g = surface_growth(s.vertices, 1.5 * s.vertices, s.faces, 2.0);
  for (Index f = 0; f < s.faces.rows(); ++f) {
    CHECK_NEAR(g.stretches(f, 0), 1.5, 1e-12);
    CHECK_NEAR(g.stretches(f, 1), 1.5, 1e-12);
    CHECK(std::isnan(g.major(f, 0)) && std::isnan(g.minor(f, 2)));
    CHECK(g.normal_velocity(f) > 0);  // outward triangles, growing
  }
}

void test_axis_stretch() {
  Points3 before(3, 3), after(3, 3);
  before << 1, 0, -0.1, 1, 0.1, 0.05, 1, -0.1, 0.08;
  after = before;
  after.col(2) *= 1.6;
  Faces faces(1, 3);
  faces << 0, 1, 2;
  const auto g = surface_growth(before, after, faces, 1.0);
  CHECK_NEAR(g.stretches(0, 0), 1.6, 1e-12);
  CHECK_NEAR(g.stretches(0, 1), 1.0, 1e-12);
  CHECK_NEAR(std::abs(g.major(0, 2)), 1.0, 1e-12);
  CHECK_NEAR(std::abs(g.minor(0, 1)), 1.0, 1e-12);
  CHECK_NEAR(g.normal_velocity(0), 0.0, 1e-12);  // the triangle moves in its own plane
  CHECK_THROWS(surface_growth(before, after.topRows(2), faces, 1.0), InvalidInput);
  CHECK_THROWS(surface_growth(before, after, faces, 0.0), InvalidInput);
}

void test_curve() {
  Points2 square(4, 2);
  square << 0, 0, 1, 0, 1, 1, 0, 1;  // counter-clockwise
  Points2 moved = square;
  moved.col(0) *= 3.0;  // stretched along x: bottom and top three times longer, pushed apart
  Segments segments(4, 2);
  segments << 0, 1, 1, 2, 2, 3, 3, 0;
  const auto g = curve_growth(square, moved, segments, 0.5, true);
  CHECK_NEAR(g.stretch(0), 3.0, 1e-12);
  CHECK_NEAR(g.stretch(1), 1.0, 1e-12);
  CHECK_NEAR(g.normal_velocity(1), 4.0, 1e-12);  // the right side moves out by 2 in 0.5
  CHECK_NEAR(g.normal_velocity(3), 0.0, 1e-12);
  CHECK_NEAR(g.tangential_velocity(0, 0), 2.0, 1e-12);  // the bottom's middle slides by 1
  Segments bad(1, 2);
  bad << 0, 4;
  CHECK_THROWS(curve_growth(square, moved, bad, 1.0, true), InvalidInput);
}

}  // namespace

int main() {
  test_scaling();
  test_axis_stretch();
  test_curve();
  TEST_MAIN_END();
}
