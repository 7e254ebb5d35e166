// Quality measures on fields whose arc lengths and areas are known by hand. Random fields against
// a brute-force reference and the paper's Table 1 are in tests/test_quality.py.
#include <morphomap/errors.hpp>
#include <morphomap/quality.hpp>

#include "check.hpp"

#include <cmath>
#include <limits>

using morphomap::DisplacementField2;
using morphomap::Index;
using morphomap::InvalidInput;
using morphomap::Points2;
using morphomap::quality;

namespace {

const double kPi = std::acos(-1.0);

Points2 circle(double r, Index n) {
  Points2 p(n, 2);
  for (Index i = 0; i < n; ++i) p.row(i) << r * std::cos(2 * kPi * i / n), r * std::sin(2 * kPi * i / n);
  return p;
}

Points2 rows(std::initializer_list<std::pair<double, double>> xy) {
  Points2 p(static_cast<Index>(xy.size()), 2);
  Index i = 0;
  for (const auto& [x, y] : xy) p.row(i++) << x, y;
  return p;
}

DisplacementField2 field(Points2 starts, Points2 ends) { return {std::move(starts), std::move(ends), {}}; }

Points2 reversed(const Points2& p) { return p.colwise().reverse(); }

// Concentric circles, radial field: every pair alike, so QM1 = QM2 = 0.
void concentric_circles() {
  const Index n = 100;
  const Points2 c1 = circle(1, n), c2 = circle(2, n);
  const auto q = quality(field(c1, c2), c1, c2);
  CHECK_NEAR(q.qm1, 0.0, 1e-12);
  CHECK_NEAR(q.qm2, 0.0, 1e-12);
  CHECK_NEAR(q.qm, 0.0, 1e-20);
  CHECK(q.crossings == 0);
  // Start half way along each chord: every area still the same (each pair walks one vertex).
  Points2 mid(n, 2), mid2(n, 2);
  for (Index i = 0; i < n; ++i) {
    mid.row(i) = 0.5 * (c1.row(i) + c1.row((i + 1) % n));
    mid2.row(i) = 2.0 * mid.row(i);
  }
  const auto h = quality(field(mid, mid2), c1, c2);
  CHECK_NEAR(h.qm1, 0.0, 1e-12);
  CHECK_NEAR(h.qm2, 0.0, 1e-12);
}

// Unit square onto the square of side 3 about the same centre (perimeters 4 and 12, alpha = 3).
// Starts at arc 0.5, 1.5 and 2.75 on c1, so l = 1, 1.25, 1.75 with 1, 1 and 2 corners between.
void squares() {
  const Points2 c1 = rows({{0, 0}, {1, 0}, {1, 1}, {0, 1}});
  const Points2 c2 = rows({{-1, -1}, {2, -1}, {2, 2}, {-1, 2}});
  const Points2 starts = rows({{0.5, 0}, {1, 0.5}, {0.25, 1}});
  // Radially scaled by 3: L = 3 l, and A_i = 8 times the fan of the centre over arc i, whose
  // areas are 0.25, 0.3125 and 0.4375.
  const auto q = quality(field(starts, rows({{0.5, -1}, {2, 0.5}, {-0.25, 2}})), c1, c2);
  CHECK_NEAR(q.qm1, 0.0, 1e-15);
  const double qm2 =
      (std::pow(2.0 / (8.0 / 3) - 1, 2) + std::pow(2.5 / (8.0 / 3) - 1, 2) + std::pow(3.5 / (8.0 / 3) - 1, 2)) / 3;
  CHECK_NEAR(q.qm2, qm2, 1e-15);
  CHECK(q.crossings == 0);

  // P_1 moved to the corner (2, 2): c2 arcs 1.5, 6, 8.25, so L = 4.5, 2.25, 5.25 and
  // L / (alpha l) = 1.5, 0.6, 1. Areas by the shoelace of each polygon: 2.75, 1.75, 3.5.
  const Points2 ends = rows({{0.5, -1}, {2, 2}, {-0.25, 2}});
  const auto r = quality(field(starts, ends), c1, c2);
  CHECK_NEAR(r.qm1, (0.25 + 0.16 + 0.0) / 3, 1e-15);
  CHECK_NEAR(r.qm2, 37.0 / 512, 1e-15);
  CHECK_NEAR(r.qm, r.qm1 * r.qm2, 0.0);
  // The same pairs walked the other way round, and the curves given the other way round.
  const auto b = quality(field(reversed(starts), reversed(ends)), reversed(c1), reversed(c2));
  CHECK_NEAR(b.qm1, r.qm1, 1e-15);
  CHECK_NEAR(b.qm2, r.qm2, 1e-15);
  // Far from the origin: the areas are summed relative to a point of each polygon.
  Points2 s1 = starts, e1 = ends, d1 = c1, d2 = c2;
  for (Points2* p : {&s1, &e1, &d1, &d2}) p->rowwise() += Eigen::RowVector2d(1e6, -3e6);
  const auto far = quality(field(s1, e1), d1, d2);
  CHECK_NEAR(far.qm1, r.qm1, 1e-9);
  CHECK_NEAR(far.qm2, r.qm2, 1e-9);
}

// Radial field on concentric circles with vectors 3 and 4 swapped: one crossing, and the pairs
// (2,3), (3,4), (4,5) have L / (alpha l) = 2, 1, 2 (alpha = 2: both polygons regular).
void swapped_neighbours() {
  const Index n = 40;
  const Points2 c1 = circle(1, n), c2 = circle(2, n);
  Points2 ends = c2;
  ends.row(3) = c2.row(4), ends.row(4) = c2.row(3);
  const auto q = quality(field(c1, ends), c1, c2);
  CHECK(q.crossings == 1);
  CHECK_NEAR(q.qm1, 2.0 / n, 1e-13);
  CHECK(q.qm2 > 0.0);
}

// Open curves: alpha = 2 and L = 2 l; trapezoids of area 0.75 and 2.25, so QM2 = 0.25.
void open_curves() {
  const Points2 c1 = rows({{0, 0}, {1, 0}, {2, 0}});
  const Points2 c2 = rows({{0, 1}, {2, 1}, {4, 1}});
  const Points2 starts = rows({{0, 0}, {0.5, 0}, {2, 0}});
  const Points2 ends = rows({{0, 1}, {1, 1}, {4, 1}});
  const auto q = quality(field(starts, ends), c1, c2, false);
  CHECK_NEAR(q.qm1, 0.0, 1e-15);
  CHECK_NEAR(q.qm2, 0.25, 1e-15);
  const auto b = quality(field(reversed(starts), reversed(ends)), c1, c2, false);
  CHECK_NEAR(b.qm1, 0.0, 1e-15);
  CHECK_NEAR(b.qm2, 0.25, 1e-15);
  // Closed, the same field gains the pair (2, 0) and c1, c2 their closing segments.
  const auto c = quality(field(starts, ends), c1, c2, true);
  CHECK(std::isfinite(c.qm1) && std::isfinite(c.qm2));
}

// A NaN row drops the two pairs it belongs to; coincident starts drop out of QM1 only.
void skipped_pairs() {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const Index n = 12;
  const Points2 c1 = circle(1, n), c2 = circle(2, n);
  Points2 ends = c2;
  ends.row(5) << nan, nan;
  // Vector 5 would break the uniformity; without it the other 10 pairs are all alike.
  const auto q = quality(field(c1, ends), c1, c2);
  CHECK_NEAR(q.qm1, 0.0, 1e-13);
  CHECK_NEAR(q.qm2, 0.0, 1e-13);

  // Start 1 repeats start 0 (l_0 = 0); its end is at P_2 so that no vector crosses another.
  Points2 starts = c1, e = c2;
  starts.row(1) = c1.row(0);
  e.row(1) = c2.row(2);
  const auto r = quality(field(starts, e), c1, c2);
  // Pairs with l > 0: (1,2) has l = 2 chords, L = 0 -> 1; the other n - 2 are exact -> 0.
  CHECK_NEAR(r.qm1, 1.0 / (n - 1), 1e-13);

  Points2 lone = c1.topRows(1);
  const auto none = quality(field(lone, c2.topRows(1)), c1, c2, false);
  CHECK(std::isnan(none.qm1) && std::isnan(none.qm2) && std::isnan(none.qm));
}

void bad_input() {
  const Points2 c1 = circle(1, 10), c2 = circle(2, 10);
  CHECK_THROWS(quality(field(c1, c2.topRows(9)), c1, c2), InvalidInput);
  CHECK_THROWS(quality(field(c1, c2), c2, c1), InvalidInput);  // points off their curves
  CHECK_THROWS(quality(field(c1, c2), c1.topRows(2), c2), InvalidInput);
  Points2 bad = c1;
  bad(3, 1) = std::numeric_limits<double>::infinity();
  CHECK_THROWS(quality(field(c1, c2), bad, c2), InvalidInput);
  try {
    quality(field(c1, 1.5 * c2), c1, c2);
    CHECK(false);
  } catch (const InvalidInput& e) {
    CHECK(std::string(e.what()).rfind("field: end point 0 is not on c2", 0) == 0);
  }
}

}  // namespace

int main() {
  concentric_circles();
  squares();
  swapped_neighbours();
  open_curves();
  skipped_pairs();
  bad_input();
  TEST_MAIN_END();
}
