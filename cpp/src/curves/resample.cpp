#include <morphomap/resample.hpp>

#include "common/validation.hpp"
#include "curves/spline.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>

namespace morphomap {
namespace {

using detail::PiecewiseCubic;

// More output points than this is a mistake, not a request (16 GB of coordinates).
constexpr Index max_points = 1'000'000'000;

// Gauss-Legendre rule of order 10 on [-1, 1], computed once by Newton's method on P_10.
struct GaussLegendre {
  static constexpr int order = 10;
  std::array<double, order> nodes{}, weights{};
  GaussLegendre() {
    const double pi = std::acos(-1.0);
    for (int i = 0; i < order; ++i) {
      double x = std::cos(pi * (i + 0.75) / (order + 0.5));
      double dp = 1.0;
      for (int iter = 0; iter < 100; ++iter) {
        double p0 = 1.0, p1 = x;  // Legendre recurrence up to P_order
        for (int k = 2; k <= order; ++k) {
          const double p2 = ((2.0 * k - 1.0) * x * p1 - (k - 1.0) * p0) / k;
          p0 = p1;
          p1 = p2;
        }
        dp = order * (x * p1 - p0) / (x * x - 1.0);
        const double dx = p1 / dp;
        x -= dx;
        if (std::abs(dx) < 1e-17) break;
      }
      nodes[i] = x;
      weights[i] = 2.0 / ((1.0 - x * x) * dp * dp);
    }
  }
};

const GaussLegendre& gauss_legendre() {
  static const GaussLegendre rule;
  return rule;
}

constexpr double eps = 2.220446049250313e-16;
// Relative accuracy asked of the quadrature.
constexpr double quad_rtol = 1e-14;

// Arc length of the pieces of one curve: speed |P'(s)| integrated by adaptive Gauss-Legendre.
class ArcLength {
 public:
  explicit ArcLength(const PiecewiseCubic& curve, bool straight) : curve_(curve), straight_(straight) {}

  // Length of piece i from s = 0 to s, with absolute tolerance tol.
  double length(Index i, double s, double tol) const {
    if (straight_) return s;
    if (s <= 0.0) return 0.0;
    const double whole = rule(i, 0.0, s);
    return adapt(i, 0.0, s, whole, tol, 30);
  }

  double speed(Index i, double s) const { return straight_ ? 1.0 : curve_.derivative(i, s).norm(); }

 private:
  double rule(Index i, double a, double b) const {
    const GaussLegendre& gl = gauss_legendre();
    const double half = 0.5 * (b - a), mid = 0.5 * (a + b);
    double sum = 0.0;
    for (int k = 0; k < GaussLegendre::order; ++k) {
      sum += gl.weights[k] * curve_.derivative(i, mid + half * gl.nodes[k]).norm();
    }
    return half * sum;
  }

  // Bisect until the two halves agree with the whole; the halves are then far more accurate
  // than the difference says, since the rule is of high order.
  double adapt(Index i, double a, double b, double whole, double tol, int depth) const {
    const double m = 0.5 * (a + b);
    const double left = rule(i, a, m), right = rule(i, m, b);
    const double both = left + right;
    // The floors keep rounding noise from driving the bisection to full depth, which is 2^depth
    // rules: relative noise, and the absolute noise of pieces so short that their lengths are
    // subnormal numbers (the relative tolerance is zero there).
    const double floor = std::max(64.0 * eps * both, 64.0 * std::numeric_limits<double>::min());
    // A non-finite speed (pieces too short for their slopes to be represented) cannot converge:
    // the caller rejects the length.
    if (depth == 0 || !std::isfinite(both) || std::abs(both - whole) <= std::max(tol, floor)) return both;
    return adapt(i, a, m, left, 0.5 * tol, depth - 1) + adapt(i, m, b, right, 0.5 * tol, depth - 1);
  }

  const PiecewiseCubic& curve_;
  bool straight_;
};

// The parameter s in [0, h] of piece i at which its arc length reaches r (0 <= r <= length):
// Newton on length(s) - r, falling back to bisection when a step leaves the bracket (the speed
// may vanish at a point where pchip gives both coordinates a zero slope).
double invert(const ArcLength& arc, Index i, double h, double length, double r) {
  if (r <= 0.0) return 0.0;
  if (r >= length) return h;
  const double tol = quad_rtol * length;
  double lo = 0.0, hi = h;
  double s = h * (r / length);
  for (int iter = 0; iter < 200; ++iter) {
    const double g = arc.length(i, s, tol) - r;
    if (g == 0.0) return s;
    (g > 0.0 ? hi : lo) = s;
    const double v = arc.speed(i, s);
    double next = v > 0.0 ? s - g / v : lo - 1.0;
    if (!(next > lo && next < hi)) next = 0.5 * (lo + hi);
    // Newton converges quadratically, so a step this small leaves an error far below it.
    if (std::abs(next - s) <= 1e-14 * h || hi - lo <= 4e-16 * h) return next;
    s = next;
  }
  return s;
}

PiecewiseCubic interpolant(const Points2& p, bool closed, ResampleMethod method) {
  switch (method) {
    case ResampleMethod::linear:
      return detail::polyline(p, closed);
    case ResampleMethod::spline:
      return detail::cubic_spline(p, closed);
    case ResampleMethod::pchip:
      return detail::pchip(p, closed);
  }
  detail::invalid("method", "unknown resampling method");
}

}  // namespace

Points2 resample(const Points2Ref& points, Index n, bool closed, ResampleMethod method) {
  const Points2 p = detail::without_repeats(points, closed, "points");
  const Index min_n = closed ? 3 : 2;
  if (n < min_n) {
    detail::invalid("n", std::string("resampling a") + (closed ? " closed" : "n open") + " curve needs at least " +
                             std::to_string(min_n) + " points, got " + std::to_string(n));
  }
  if (n > max_points) {
    detail::invalid("n", "at most " + std::to_string(max_points) + " points, got " + std::to_string(n));
  }

  const PiecewiseCubic curve = interpolant(p, closed, method);
  const bool straight = method == ResampleMethod::linear;
  const ArcLength arc(curve, straight);
  const Index pieces = curve.pieces();
  if (!std::isfinite(curve.h.sum())) {
    detail::invalid("points", "the curve is too long to measure (its length overflows)");
  }
  if (!straight && curve.h.minCoeff() < std::numeric_limits<double>::min()) {
    detail::invalid("points",
                    "consecutive points too close together to fit a curve through them (closer "
                    "than the smallest normal double)");
  }

  // Length of each piece, then cumulative lengths with compensated summation so that the
  // spacing does not drift along curves of many pieces.
  Vector piece_length(pieces);
  tbb::parallel_for(tbb::blocked_range<Index>(0, pieces, 256), [&](const auto& range) {
    for (Index i = range.begin(); i != range.end(); ++i) {
      // The chord is a lower bound of the piece's length, so this tolerance is relative.
      piece_length(i) = arc.length(i, curve.h(i), quad_rtol * curve.h(i));
    }
  });
  Vector start(pieces + 1);
  start(0) = 0.0;
  double sum = 0.0, carry = 0.0;
  for (Index i = 0; i < pieces; ++i) {
    const double x = piece_length(i), t = sum + x;
    carry += std::abs(sum) >= std::abs(x) ? (sum - t) + x : (x - t) + sum;
    sum = t;
    start(i + 1) = sum + carry;
  }
  const double total = start(pieces);
  if (!(total > 0.0) || !std::isfinite(total)) {
    detail::invalid("points", "the curve's length is zero or overflows");
  }

  Points2 out(n, 2);
  const Index intervals = closed ? n : n - 1;
  const Index grain = straight ? 4096 : 256;
  tbb::parallel_for(tbb::blocked_range<Index>(0, n, grain), [&](const auto& range) {
    for (Index k = range.begin(); k != range.end(); ++k) {
      const double target = static_cast<double>(k) * total / static_cast<double>(intervals);
      Index i = std::upper_bound(start.data(), start.data() + pieces, target) - start.data() - 1;
      i = std::clamp<Index>(i, 0, pieces - 1);
      const double r = std::clamp(target - start(i), 0.0, piece_length(i));
      const double s = straight ? std::min(r, curve.h(i)) : invert(arc, i, curve.h(i), piece_length(i), r);
      out.row(k) = curve.position(i, s).transpose();
    }
  });
  out.row(0) = p.row(0);
  if (!closed) out.row(n - 1) = p.row(p.rows() - 1);
  return out;
}

}  // namespace morphomap
