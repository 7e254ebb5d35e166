#pragma once
// A curve walked by arc length: points at arc positions and the pieces between two positions.
#include <morphomap/types.hpp>

namespace morphomap::detail {

class ArcCurve {
 public:
  // The curve as checked by require_curve (a closing duplicate is dropped; repeats are kept).
  ArcCurve(const Points2Ref& points, bool closed, const char* name);
  // A curve that passed require_curve already (at its caller's entry).
  static ArcCurve unchecked(const Points2Ref& points, bool closed);

  const Points2& points() const { return points_; }
  bool closed() const { return closed_; }
  double length() const { return length_; }
  Index size() const { return points_.rows(); }
  // Arc position of point i (i == size() gives the length: the closing point of a closed curve).
  double arc(Index i) const { return arc_[i]; }

  // Position s reduced to [0, length) on a closed curve, clamped to [0, length] on an open one.
  double wrap(double s) const;
  // Distance along the curve from position a to position b: forward on a closed curve
  // (wrapping), |b - a| on an open one.
  double forward(double a, double b) const;
  // The shorter of the two ways between a and b on a closed curve, |b - a| on an open one.
  double between(double a, double b) const;

  Vec2 point_at(double s) const;
  // The polyline from position a to position b: forward (wrapping) on a closed curve, in the
  // direction of b on an open one; both end points included, the vertices between in order.
  Points2 piece(double a, double b) const;
  // The segment containing the wrapped position s: the last one starting at or before it.
  Index segment_at(double s) const;
  // The first vertex whose arc position lies after s (size() if none).
  Index vertex_after(double s) const;

 private:
  ArcCurve(const Points2Ref& points, bool closed, Index n);

  Points2 points_;
  Vector arc_;  // size() + 1 entries
  bool closed_;
  double length_;
};

}  // namespace morphomap::detail
