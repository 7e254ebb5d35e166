#include "curves/spline.hpp"

#include <cmath>
#include <vector>

namespace morphomap::detail {
namespace {

// Pieces of the curve: chord lengths and chord slopes (p[i+1] - p[i]) / h[i].
struct Chords {
  Index m = 0;  // number of points
  Index pieces = 0;
  Vector h;
  Points2 slope;
};

Chords chords(const Points2& p, bool closed) {
  Chords ch;
  ch.m = p.rows();
  ch.pieces = closed ? ch.m : ch.m - 1;
  ch.h.resize(ch.pieces);
  ch.slope.resize(ch.pieces, 2);
  for (Index i = 0; i < ch.pieces; ++i) {
    const Index j = (i + 1) % ch.m;
    const double dx = p(j, 0) - p(i, 0), dy = p(j, 1) - p(i, 1);
    ch.h(i) = std::hypot(dx, dy);
    ch.slope(i, 0) = dx / ch.h(i);
    ch.slope(i, 1) = dy / ch.h(i);
  }
  return ch;
}

PiecewiseCubic empty_curve(const Points2& p, const Chords& ch) {
  PiecewiseCubic curve;
  curve.h = ch.h;
  curve.a = p.topRows(ch.pieces);
  curve.b = ch.slope;
  curve.c = Points2::Zero(ch.pieces, 2);
  curve.d = Points2::Zero(ch.pieces, 2);
  return curve;
}

// Fills the pieces from values p and slopes t at the points (cubic Hermite).
void hermite(const Points2& p, const Points2& t, const Chords& ch, PiecewiseCubic& curve) {
  for (Index i = 0; i < ch.pieces; ++i) {
    const Index j = (i + 1) % ch.m;
    const double h = ch.h(i);
    for (int k = 0; k < 2; ++k) {
      const double delta = ch.slope(i, k);
      curve.b(i, k) = t(i, k);
      curve.c(i, k) = (3.0 * delta - 2.0 * t(i, k) - t(j, k)) / h;
      curve.d(i, k) = (t(i, k) + t(j, k) - 2.0 * delta) / (h * h);
    }
  }
}

// Solves the tridiagonal system sub[i] x[i-1] + diag[i] x[i] + sup[i] x[i+1] = rhs[i] (Thomas;
// no pivoting, which the diagonally dominant spline systems do not need). Two right-hand sides.
Points2 solve_tridiagonal(const std::vector<double>& sub, std::vector<double> diag, const std::vector<double>& sup,
                          Points2 rhs) {
  const Index n = rhs.rows();
  for (Index i = 1; i < n; ++i) {
    const double w = sub[i] / diag[i - 1];
    diag[i] -= w * sup[i - 1];
    rhs.row(i) -= w * rhs.row(i - 1);
  }
  rhs.row(n - 1) /= diag[n - 1];
  for (Index i = n - 2; i >= 0; --i) {
    rhs.row(i) = (rhs.row(i) - sup[i] * rhs.row(i + 1)) / diag[i];
  }
  return rhs;
}

// Same with the corner entries sub[0] (row 0, column n-1) and sup[n-1] (row n-1, column 0), by
// Sherman-Morrison: A = T + u v^T with u = (g, 0, ..., 0, sup[n-1]), v = (1, 0, ..., 0, sub[0]/g).
Points2 solve_cyclic(const std::vector<double>& sub, std::vector<double> diag, const std::vector<double>& sup,
                     const Points2& rhs) {
  const Index n = rhs.rows();
  const double g = -diag[0];
  const double alpha = sup[n - 1], beta = sub[0];
  diag[0] -= g;
  diag[n - 1] -= alpha * beta / g;
  const Points2 y = solve_tridiagonal(sub, diag, sup, rhs);
  Points2 u = Points2::Zero(n, 2);
  u.col(0)(0) = g;
  u.col(0)(n - 1) = alpha;
  const Points2 z = solve_tridiagonal(sub, diag, sup, u);  // column 1 unused
  const double vz = z(0, 0) + beta / g * z(n - 1, 0);
  Points2 x = y;
  for (int k = 0; k < 2; ++k) {
    const double vy = y(0, k) + beta / g * y(n - 1, k);
    x.col(k) -= (vy / (1.0 + vz)) * z.col(0);
  }
  return x;
}

// The scipy one-sided end slope: a three-point estimate, kept monotone.
double pchip_end_slope(double h0, double h1, double m0, double m1) {
  double d = ((2.0 * h0 + h1) * m0 - h0 * m1) / (h0 + h1);
  const auto sign = [](double v) { return (v > 0) - (v < 0); };
  if (sign(d) != sign(m0)) {
    d = 0.0;
  } else if (sign(m0) != sign(m1) && std::abs(d) > 3.0 * std::abs(m0)) {
    d = 3.0 * m0;
  }
  return d;
}

// Weighted harmonic mean of the chord slopes on both sides of a point; zero at an extremum.
double pchip_inner_slope(double h_left, double h_right, double m_left, double m_right) {
  if (m_left == 0.0 || m_right == 0.0 || (m_left > 0) != (m_right > 0)) return 0.0;
  const double w1 = 2.0 * h_right + h_left, w2 = h_right + 2.0 * h_left;
  return (w1 + w2) / (w1 / m_left + w2 / m_right);
}

}  // namespace

PiecewiseCubic polyline(const Points2& points, bool closed) {
  const Chords ch = chords(points, closed);
  return empty_curve(points, ch);
}

PiecewiseCubic cubic_spline(const Points2& points, bool closed) {
  const Chords ch = chords(points, closed);
  PiecewiseCubic curve = empty_curve(points, ch);
  const Index m = ch.m;
  // Second derivatives M at the points: h[i-1] M[i-1] + 2 (h[i-1] + h[i]) M[i] + h[i] M[i+1]
  // = 6 (slope[i] - slope[i-1]) at every point with a piece on each side.
  Points2 second = Points2::Zero(m, 2);
  if (closed) {
    std::vector<double> sub(m), diag(m), sup(m);
    Points2 rhs(m, 2);
    for (Index i = 0; i < m; ++i) {
      const Index l = (i + m - 1) % m;
      sub[i] = ch.h(l);
      diag[i] = 2.0 * (ch.h(l) + ch.h(i));
      sup[i] = ch.h(i);
      rhs.row(i) = 6.0 * (ch.slope.row(i) - ch.slope.row(l));
    }
    second = solve_cyclic(sub, diag, sup, rhs);
  } else if (m > 2) {
    const Index k = m - 2;  // unknowns M[1] .. M[m-2]; natural ends M[0] = M[m-1] = 0
    std::vector<double> sub(k), diag(k), sup(k);
    Points2 rhs(k, 2);
    for (Index r = 0; r < k; ++r) {
      const Index i = r + 1;
      sub[r] = r > 0 ? ch.h(i - 1) : 0.0;
      diag[r] = 2.0 * (ch.h(i - 1) + ch.h(i));
      sup[r] = r + 1 < k ? ch.h(i) : 0.0;
      rhs.row(r) = 6.0 * (ch.slope.row(i) - ch.slope.row(i - 1));
    }
    second.middleRows(1, k) = solve_tridiagonal(sub, diag, sup, rhs);
  }
  for (Index i = 0; i < ch.pieces; ++i) {
    const Index j = (i + 1) % m;
    const double h = ch.h(i);
    curve.b.row(i) = ch.slope.row(i) - h * (2.0 * second.row(i) + second.row(j)) / 6.0;
    curve.c.row(i) = second.row(i) / 2.0;
    curve.d.row(i) = (second.row(j) - second.row(i)) / (6.0 * h);
  }
  return curve;
}

PiecewiseCubic pchip(const Points2& points, bool closed) {
  const Chords ch = chords(points, closed);
  PiecewiseCubic curve = empty_curve(points, ch);
  const Index m = ch.m;
  Points2 t(m, 2);
  for (int k = 0; k < 2; ++k) {
    for (Index i = 0; i < m; ++i) {
      if (!closed && (i == 0 || i == m - 1)) continue;
      const Index l = (i + m - 1) % m;
      t(i, k) = pchip_inner_slope(ch.h(l), ch.h(i), ch.slope(l, k), ch.slope(i, k));
    }
    if (!closed) {
      const Index p = ch.pieces;
      if (m == 2) {  // scipy: the straight segment
        t(0, k) = t(1, k) = ch.slope(0, k);
      } else {
        t(0, k) = pchip_end_slope(ch.h(0), ch.h(1), ch.slope(0, k), ch.slope(1, k));
        t(m - 1, k) = pchip_end_slope(ch.h(p - 1), ch.h(p - 2), ch.slope(p - 1, k), ch.slope(p - 2, k));
      }
    }
  }
  hermite(points, t, ch, curve);
  return curve;
}

}  // namespace morphomap::detail
