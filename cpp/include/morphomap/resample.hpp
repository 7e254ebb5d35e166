#pragma once
// Equal-arc-length resampling of a curve (the paper's interparc).
#include <morphomap/types.hpp>

namespace morphomap {

enum class ResampleMethod {
  linear,  // along the polyline
  spline,  // C2 cubic spline on the chord-length parameter; periodic when closed, natural ends when open
  pchip,   // shape-preserving piecewise cubic Hermite (Fritsch-Carlson) on the chord-length parameter
};

// n points equally spaced in arc length along the curve, starting at its first point. Arc length is
// measured along the interpolant itself (the polyline, the spline or the pchip curve). Open curves
// keep both end points; closed curves do not repeat the first point. Exact consecutive repeats of
// input points are dropped first. The spacing is length / n when closed, length / (n - 1) when
// open. Needs n >= 3 (closed) or n >= 2 (open), and n <= 1e9. Throws InvalidInput naming
// "points" or "n".
Points2 resample(const Points2Ref& points, Index n, bool closed = true, ResampleMethod method = ResampleMethod::linear);

}  // namespace morphomap
