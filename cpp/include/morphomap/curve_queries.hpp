#pragma once
// Queries of many points or lines against one polyline, and curve-curve intersections.
#include <morphomap/types.hpp>

#include <memory>

namespace morphomap {

// One answer per query; rows of a query that found nothing are NaN (segments: -1).
struct CurveHits {
  Points2 points;        // the point found on the curve
  Vector distances;      // closest points: Euclidean distance; lines: signed distance along the
                         // unit direction from the origin to the point
  IndexVector segments;  // segment i runs from point i to point i+1 (wrapping on a closed curve)
  Vector arc_lengths;    // arc-length parameter of the point, measured from the first point
};

namespace detail {
struct CurveIndexUnchecked;  // the core's unchecked access, for curves it checked at its entry
}

// A polyline with a bounding-volume hierarchy over its segments, built once and queried many
// times from all cores. Zero-length segments are allowed (a repeated point).
class CurveIndex {
 public:
  CurveIndex(const Points2Ref& curve, bool closed = true);
  ~CurveIndex();
  CurveIndex(CurveIndex&&) noexcept;
  CurveIndex& operator=(CurveIndex&&) noexcept;

  // Closest point on the curve to each query point (ties: the lowest segment index).
  CurveHits closest_points(const Points2Ref& queries) const;

  // For each line origin + t * direction, t of either sign, the intersection with the curve
  // nearest to the origin (ties: the positive side, then the lowest segment index).
  CurveHits line_intersections(const Points2Ref& origins, const Points2Ref& directions) const;

  Index size() const;  // number of points
  bool closed() const;

 private:
  friend struct detail::CurveIndexUnchecked;
  struct Impl;
  explicit CurveIndex(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

CurveHits closest_points(const Points2Ref& queries, const Points2Ref& curve, bool closed = true);
CurveHits line_intersections(const Points2Ref& origins, const Points2Ref& directions, const Points2Ref& curve,
                             bool closed = true);

// The points where c2 crosses c1, in order along c1.
struct CurveIntersections {
  Points2 points;
  Vector arc_lengths1;  // on c1
  Vector arc_lengths2;  // on c2
  IndexVector segments1;
  IndexVector segments2;
};

// Crossings are decided with exact predicates under a symbolic perturbation: c2 shifted by
// ε(1, δ), ε infinitesimal and δ infinitesimally smaller still (to the right, then up). Every
// contact then becomes a proper crossing or no contact at all, so touching points and collinear
// overlaps have a defined answer, and two closed curves cross an even number of times.
// - A touch at one point (a vertex of one curve on the other) where c2 does not pass to the
//   other side of c1 is not reported; where c2 does pass, it is reported once. (When the shift
//   turns such a touch into two crossings at one point that are neighbours along both curves,
//   both are dropped.)
// - A shared stretch (collinear overlap) is crossed where the shift puts it: c2 passing through
//   gives one crossing, at one end of the stretch; c2 leaving on the side it came from gives
//   none or two, at the two ends, depending on which side the shift moves c2 to.
// Points, parameters and arc lengths come from the unperturbed segments; a crossing at a vertex
// is exactly that vertex. Ties in the order along c1 go by arc length on c2. Exact consecutive
// repeats of points are ignored; segments1/segments2 index the given rows (segment i runs from
// row i to the next). Both curves are closed unless closed is false.
CurveIntersections curve_intersections(const Points2Ref& c1, const Points2Ref& c2, bool closed = true);

}  // namespace morphomap
