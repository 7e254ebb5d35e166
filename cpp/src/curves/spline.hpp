#pragma once
// Planar curves made of cubic pieces through given points, parameterised by cumulative chord
// length: the interpolants behind resample.
#include <morphomap/types.hpp>

namespace morphomap::detail {

// Piece i is a(i) + b(i) s + c(i) s^2 + d(i) s^3 for the local parameter s in [0, h(i)], where
// h(i) is the chord from point i to point i + 1 (wrapping to point 0 when closed). Piece i starts
// exactly at point i. Points must be finite with no consecutive repeats (nor a closing repeat).
struct PiecewiseCubic {
  Vector h;
  Points2 a, b, c, d;

  Index pieces() const { return h.size(); }
  Vec2 position(Index i, double s) const {
    return a.row(i).transpose() + s * (b.row(i).transpose() + s * (c.row(i).transpose() + s * d.row(i).transpose()));
  }
  Vec2 derivative(Index i, double s) const {
    return b.row(i).transpose() + s * (2.0 * c.row(i).transpose() + 3.0 * s * d.row(i).transpose());
  }
};

// The polyline itself (c = d = 0, |b| = 1).
PiecewiseCubic polyline(const Points2& points, bool closed);

// The C2 cubic spline: periodic when closed, natural (zero second derivative) at both ends when
// open. Two open points give the straight segment.
PiecewiseCubic cubic_spline(const Points2& points, bool closed);

// Fritsch-Carlson monotone piecewise cubic Hermite, per coordinate, with the slopes of scipy's
// PchipInterpolator: weighted harmonic means inside, its one-sided three-point formula at the ends
// of an open curve, and the inside formula across the wrap of a closed curve.
PiecewiseCubic pchip(const Points2& points, bool closed);

}  // namespace morphomap::detail
