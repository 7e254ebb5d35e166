// Equal-arc-length resampling (interparc). The spacing of the spline and pchip methods against an
// independent reference is checked more tightly in tests/test_resample.py (scipy).
#include <morphomap/errors.hpp>
#include <morphomap/resample.hpp>

#include "check.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

using morphomap::Index;
using morphomap::InvalidInput;
using morphomap::Points2;
using morphomap::resample;
using morphomap::ResampleMethod;

namespace {

const double pi = std::acos(-1.0);
const ResampleMethod methods[] = {ResampleMethod::linear, ResampleMethod::spline, ResampleMethod::pchip};

Points2 regular_polygon(Index m, double radius = 1.0) {
  Points2 p(m, 2);
  for (Index i = 0; i < m; ++i) {
    p(i, 0) = radius * std::cos(2 * pi * i / m);
    p(i, 1) = radius * std::sin(2 * pi * i / m);
  }
  return p;
}

double dist(const Points2& p, Index i, const Points2& q, Index j) { return (p.row(i) - q.row(j)).norm(); }

// The message of the InvalidInput that f throws, or "" when it throws none.
template <class F>
std::string invalid_message(F f) {
  try {
    f();
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "";
}

bool starts_with(const std::string& s, const std::string& prefix) { return s.compare(0, prefix.size(), prefix) == 0; }

void test_invalid_input() {
  const Points2 tri = regular_polygon(3);
  Points2 nan = tri;
  nan(1, 0) = std::numeric_limits<double>::quiet_NaN();
  Points2 inf = tri;
  inf(2, 1) = std::numeric_limits<double>::infinity();
  Points2 one(1, 2);
  one << 1, 2;
  Points2 same(4, 2);
  same << 1, 2, 1, 2, 1, 2, 1, 2;
  Points2 two(2, 2);
  two << 0, 0, 1, 0;
  Points2 two_repeated(3, 2);  // closed: the last point repeats the first
  two_repeated << 0, 0, 1, 0, 0, 0;

  for (ResampleMethod m : methods) {
    CHECK(starts_with(invalid_message([&] { resample(nan, 10, true, m); }), "points: "));
    CHECK(starts_with(invalid_message([&] { resample(inf, 10, false, m); }), "points: "));
    CHECK(starts_with(invalid_message([&] { resample(one, 10, false, m); }), "points: "));
    CHECK(starts_with(invalid_message([&] { resample(same, 10, false, m); }), "points: "));
    CHECK(starts_with(invalid_message([&] { resample(same, 10, true, m); }), "points: "));
    CHECK(starts_with(invalid_message([&] { resample(two, 10, true, m); }), "points: "));
    CHECK(starts_with(invalid_message([&] { resample(two_repeated, 10, true, m); }), "points: "));
    CHECK(starts_with(invalid_message([&] { resample(Points2(0, 2), 10, false, m); }), "points: "));
    CHECK(starts_with(invalid_message([&] { resample(two, 1, false, m); }), "n: "));
    CHECK(starts_with(invalid_message([&] { resample(two, 0, false, m); }), "n: "));
    CHECK(starts_with(invalid_message([&] { resample(two, -5, false, m); }), "n: "));
    CHECK(starts_with(invalid_message([&] { resample(tri, 2, true, m); }), "n: "));
    CHECK(starts_with(invalid_message([&] { resample(tri, Index(1) << 40, true, m); }), "n: "));
    CHECK(starts_with(invalid_message([&] { resample(tri, Index(1) << 62, false, m); }), "n: "));
  }
  // Coordinates so large that the length overflows.
  Points2 huge(3, 2);
  huge << -1e308, 0, 1e308, 0, 0, 1e308;
  CHECK(starts_with(invalid_message([&] { resample(huge, 10, true, ResampleMethod::linear); }), "points: "));
  // The smallest valid requests work.
  CHECK(resample(two, 2, false).rows() == 2);
  CHECK(resample(tri, 3, true).rows() == 3);
}

// A regular 12-gon resampled linearly: 12 points give it back, 4 a square, 24 its vertices and
// edge midpoints.
void test_linear_regular_polygon() {
  const Points2 p = regular_polygon(12, 2.0);
  const Points2 same = resample(p, 12, true);
  CHECK(same.rows() == 12);
  for (Index i = 0; i < 12; ++i) CHECK_NEAR(dist(same, i, p, i), 0.0, 1e-14);

  const Points2 square = resample(p, 4, true);
  for (Index i = 0; i < 4; ++i) CHECK_NEAR(dist(square, i, p, 3 * i), 0.0, 1e-14);

  const Points2 fine = resample(p, 24, true);
  const double half_side = 0.5 * dist(p, 0, p, 1);
  for (Index i = 0; i < 24; ++i) {
    CHECK_NEAR(dist(fine, i, fine, (i + 1) % 24), half_side, 1e-14);
    if (i % 2 == 0) CHECK_NEAR(dist(fine, i, p, i / 2), 0.0, 1e-14);
  }
}

// Unevenly spaced points on a straight line: every method follows the line (the chord-length
// parameter is arc length there), so the output is evenly spaced in plain distance.
void test_straight_line() {
  Points2 p(6, 2);
  const double t[] = {0.0, 0.1, 0.15, 0.9, 2.0, 3.0};
  for (Index i = 0; i < 6; ++i) {
    p(i, 0) = 1.0 + 0.6 * t[i];
    p(i, 1) = -2.0 + 0.8 * t[i];
  }
  for (ResampleMethod m : methods) {
    const Index n = 31;
    const Points2 out = resample(p, n, false, m);
    CHECK(out.rows() == n);
    CHECK(out.row(0) == p.row(0));
    CHECK(out.row(n - 1) == p.row(5));
    for (Index i = 0; i + 1 < n; ++i) CHECK_NEAR(dist(out, i, out, i + 1), 0.1, 1e-13);
    for (Index i = 0; i < n; ++i) {  // on the line
      CHECK_NEAR(0.8 * (out(i, 0) - 1.0) - 0.6 * (out(i, 1) + 2.0), 0.0, 1e-14);
    }
    // Resampling again changes nothing.
    const Points2 again = resample(out, n, false, m);
    CHECK_NEAR((again - out).cwiseAbs().maxCoeff(), 0.0, 1e-13);
  }
}

// Arc-length position of a point that lies on the polyline p (closed).
double position_on_polyline(const Points2& p, const Eigen::RowVector2d& q) {
  double best = std::numeric_limits<double>::infinity(), at = 0.0, start = 0.0;
  for (Index i = 0; i < p.rows(); ++i) {
    const Eigen::RowVector2d a = p.row(i), b = p.row((i + 1) % p.rows());
    const double len = (b - a).norm();
    const double t = std::clamp((q - a).dot(b - a) / (len * len), 0.0, 1.0);
    const double d = (a + t * (b - a) - q).norm();
    if (d < best) {
      best = d;
      at = start + t * len;
    }
    start += len;
  }
  return at;
}

// Linear spacing measured along an irregular polygon, with repeated points that must be dropped.
void test_linear_spacing() {
  Points2 p(7, 2);
  p << 0, 0, 3, 0.5, 3, 0.5, 4, 2, 2.5, 3.7, -1, 2, 0, 0;  // a repeat and a closing repeat
  Points2 clean(5, 2);
  clean << 0, 0, 3, 0.5, 4, 2, 2.5, 3.7, -1, 2;
  double length = 0.0;
  for (Index i = 0; i < 5; ++i) length += dist(clean, i, clean, (i + 1) % 5);

  const Index n = 97;
  const Points2 out = resample(p, n, true);
  const Points2 out_clean = resample(clean, n, true);
  CHECK(out == out_clean);
  CHECK(out.row(0) == clean.row(0));
  double worst = 0.0;
  for (Index k = 0; k < n; ++k) {
    const double expected = k * length / n;
    worst = std::max(worst, std::abs(position_on_polyline(clean, out.row(k)) - expected));
  }
  CHECK_NEAR(worst / (length / n), 0.0, 1e-12);

  // Many output points: the parallel path gives the same spacing.
  const Index big = 200001;
  const Points2 many = resample(clean, big, true);
  for (Index k = 0; k < big; k += 997) {
    CHECK_NEAR(position_on_polyline(clean, many.row(k)), k * length / big, 1e-12 * length);
  }
}

// A periodic spline through 64 samples of the unit circle stays on it to 1e-6 everywhere.
void test_spline_circle() {
  const Points2 p = regular_polygon(64);
  const Points2 out = resample(p, 10000, true, ResampleMethod::spline);
  double worst = 0.0;
  for (Index i = 0; i < out.rows(); ++i) worst = std::max(worst, std::abs(out.row(i).norm() - 1));
  CHECK(worst < 1e-6);
  // Equal arcs of a near-circle give equal chords.
  const Points2 coarse = resample(p, 10, true, ResampleMethod::spline);
  for (Index i = 0; i < 10; ++i) {
    CHECK_NEAR(dist(coarse, i, coarse, (i + 1) % 10), 2 * std::sin(pi / 10), 1e-6);
  }
}

// Arc length of the ellipse (a cos u, b sin u) from u = 0 to u, by composite Gauss-Legendre.
double ellipse_arc(double a, double b, double u) {
  const double x[3] = {-std::sqrt(0.6), 0.0, std::sqrt(0.6)}, w[3] = {5.0 / 9, 8.0 / 9, 5.0 / 9};
  const int pieces = 4000;
  double sum = 0.0;
  for (int i = 0; i < pieces; ++i) {
    const double lo = u * i / pieces, hi = u * (i + 1) / pieces;
    for (int k = 0; k < 3; ++k) {
      const double v = 0.5 * (lo + hi) + 0.5 * (hi - lo) * x[k];
      sum += 0.5 * (hi - lo) * w[k] * std::hypot(a * std::sin(v), b * std::cos(v));
    }
  }
  return sum;
}

// A spline through dense, unevenly spread samples of an ellipse is the ellipse to ~1e-10, so its
// equal arcs are the ellipse's equal arcs: an independent check of the spline's arc length.
void test_spline_ellipse_spacing() {
  const double a = 2.0, b = 1.0;
  const Index m = 400;
  Points2 p(m, 2);
  for (Index i = 0; i < m; ++i) {
    const double u = 2 * pi * i / m + 0.3 * std::sin(2 * pi * i / m);  // uneven samples
    p(i, 0) = a * std::cos(u);
    p(i, 1) = b * std::sin(u);
  }
  const double length = ellipse_arc(a, b, 2 * pi);
  const Index n = 37;
  for (ResampleMethod method : {ResampleMethod::spline, ResampleMethod::linear}) {
    const Points2 out = resample(p, n, true, method);
    double worst = 0.0;
    for (Index k = 1; k < n; ++k) {
      double u = std::atan2(out(k, 1) / b, out(k, 0) / a);
      if (u < 0) u += 2 * pi;
      worst = std::max(worst, std::abs(ellipse_arc(a, b, u) - k * length / n));
    }
    // The polyline is shorter than the ellipse by ~1e-5 relative; the spline is not.
    if (method == ResampleMethod::spline) CHECK(worst / (length / n) < 1e-7);
    if (method == ResampleMethod::linear) CHECK(worst / (length / n) > 1e-6);
  }
}

// Pchip through the corners of a square is the square itself, walked with zero speed at the
// corners: resampling gives the corners and points at equal steps along the edges.
void test_pchip_square() {
  Points2 p(4, 2);
  p << 0, 0, 1, 0, 1, 1, 0, 1;
  const Points2 out = resample(p, 12, true, ResampleMethod::pchip);
  Points2 expected(12, 2);
  for (Index k = 0; k < 12; ++k) {
    const Index edge = k / 3;
    const double t = (k % 3) / 3.0;
    expected.row(k) = (1 - t) * p.row(edge) + t * p.row((edge + 1) % 4);
  }
  CHECK_NEAR((out - expected).cwiseAbs().maxCoeff(), 0.0, 1e-12);
}

// Open curves keep both end points exactly; closed ones start at the first point.
void test_end_points() {
  Points2 p(5, 2);
  p << 0.1, 0.2, 1.3, 0.7, 2.2, -0.4, 3.1, 0.9, 4.7, 0.3;
  for (ResampleMethod m : methods) {
    for (Index n : {2, 3, 10, 1001}) {
      const Points2 open = resample(p, n, false, m);
      CHECK(open.rows() == n);
      CHECK(open.row(0) == p.row(0));
      CHECK(open.row(n - 1) == p.row(4));
      CHECK(open.allFinite());
      const Points2 closed = resample(p, n + 1, true, m);
      CHECK(closed.rows() == n + 1);
      CHECK(closed.row(0) == p.row(0));
      CHECK(closed.allFinite());
    }
  }
  // Two points, open: the segment.
  Points2 two(2, 2);
  two << 0, 0, 2, 4;
  for (ResampleMethod m : methods) {
    const Points2 out = resample(two, 5, false, m);
    for (Index k = 0; k < 5; ++k) {
      CHECK_NEAR(out(k, 0), 0.5 * k, 1e-14);
      CHECK_NEAR(out(k, 1), 1.0 * k, 1e-14);
    }
  }
}

}  // namespace

int main() {
  test_invalid_input();
  test_linear_regular_polygon();
  test_straight_line();
  test_linear_spacing();
  test_spline_circle();
  test_spline_ellipse_spacing();
  test_pchip_square();
  test_end_points();
  TEST_MAIN_END();
}
