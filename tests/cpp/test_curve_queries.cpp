// CurveIndex against closed-form answers on a square and a circle.
#include <morphomap/morphomap.hpp>

#include <cmath>

#include "check.hpp"

using namespace morphomap;

int main() {
  // Unit square, counter-clockwise; the closed curve repeats no point.
  Points2 square(4, 2);
  square << 0, 0, 1, 0, 1, 1, 0, 1;
  const CurveIndex index(square, true);
  CHECK(index.size() == 4);

  Points2 queries(3, 2);
  queries << 0.25, -2.0,  // below the bottom edge
      2.0, 0.5,           // right of the right edge
      0.5, 0.4;           // inside, nearest the bottom edge
  const CurveHits near = index.closest_points(queries);
  CHECK_NEAR(near.points(0, 0), 0.25, 0.0);
  CHECK_NEAR(near.points(0, 1), 0.0, 0.0);
  CHECK_NEAR(near.distances[0], 2.0, 1e-15);
  CHECK(near.segments[0] == 0);
  CHECK_NEAR(near.arc_lengths[0], 0.25, 1e-15);
  CHECK(near.segments[1] == 1);
  CHECK_NEAR(near.arc_lengths[1], 1.5, 1e-15);
  CHECK_NEAR(near.distances[2], 0.4, 1e-15);

  // Lines through the centre: the nearest hit is 0.5 away on either side.
  Points2 origins(2, 2), directions(2, 2);
  origins << 0.5, 0.5, 3.0, 0.5;
  directions << 0.0, -2.0, 1.0, 0.0;
  const CurveHits hits = index.line_intersections(origins, directions);
  CHECK_NEAR(hits.distances[0], 0.5, 1e-15);  // ties go to the positive side: the bottom edge
  CHECK(hits.segments[0] == 0);
  CHECK_NEAR(hits.points(0, 1), 0.0, 1e-15);
  CHECK_NEAR(hits.distances[1], -2.0, 1e-15);  // behind the origin, on the right edge
  CHECK(hits.segments[1] == 1);

  // A line that misses gives NaN and segment -1.
  Points2 far_origin(1, 2), along(1, 2);
  far_origin << 0.0, 5.0;
  along << 1.0, 0.0;
  const CurveHits miss = index.line_intersections(far_origin, along);
  CHECK(std::isnan(miss.distances[0]) && std::isnan(miss.points(0, 0)) && miss.segments[0] == -1);

  // Circle of radius 2 with 1000 points: radial lines from the centre hit at distance ~2.
  const int n = 1000;
  Points2 circle(n, 2);
  for (int i = 0; i < n; ++i) {
    const double a = 2 * M_PI * i / n;
    circle(i, 0) = 2 * std::cos(a), circle(i, 1) = 2 * std::sin(a);
  }
  const CurveIndex round(circle, true);
  Points2 centre = Points2::Zero(1, 2), up(1, 2);
  up << 0.3, 0.7;
  const CurveHits radial = round.line_intersections(centre, up);
  CHECK(std::abs(std::abs(radial.distances[0]) - 2.0) < 2 * (1 - std::cos(M_PI / n)));

  // Bad input names the argument.
  Points2 one(1, 2);
  one << 0, 0;
  CHECK_THROWS(CurveIndex(one, true), InvalidInput);
  Points2 nan_query(1, 2);
  nan_query << NAN, 0;
  CHECK_THROWS(index.closest_points(nan_query), InvalidInput);
  Points2 zero(1, 2);
  zero << 0, 0;
  CHECK_THROWS(index.line_intersections(centre, zero), InvalidInput);
  try {
    index.line_intersections(centre, zero);
  } catch (const InvalidInput& e) {
    CHECK(std::string(e.what()).rfind("directions:", 0) == 0);
  }
  TEST_MAIN_END();
}
