#pragma once
// The paper's Appendix A: a similarity transformation that brings C1 close to C2 before mapping.
#include <morphomap/types.hpp>

namespace morphomap {

// x -> centre + translation + scale * R(angle) * (x - centre): a turn and a scaling about centre,
// then a shift. align_curves returns the transformation that takes C1 near C2; apply_inverse
// takes points (the starts of a displacement field computed from the moved C1) back.
struct Similarity2 {
  Vec2 centre = Vec2::Zero();
  double scale = 1.0;
  double angle = 0.0;  // radians, counter-clockwise
  Vec2 translation = Vec2::Zero();

  Points2 apply(const Points2Ref& points) const;
  // InvalidInput when scale is zero or not finite.
  Points2 apply_inverse(const Points2Ref& points) const;
};

// Area of the intersection of the regions enclosed by two closed curves, from the exact crossings
// of their boundaries (curve_intersections): the boundary integral of (x dy - y dx) / 2 over the
// parts of each boundary inside the other. Either orientation; a closing repeat and exact
// consecutive repeats are dropped. Touching boundaries and shared stretches get the limit of an
// infinitesimal shift of b, which is the exact area. O((n + m) log(n + m) + k) for k crossings.
// Each curve must be simple: this is not checked (it would cost as much as the area itself), and
// a self-intersecting curve gives a meaningless number. InvalidInput for a non-finite
// coordinate, fewer than 3 distinct points or a zero signed area.
double overlap_area(const Points2Ref& a, const Points2Ref& b);

// Closed curves (simple, non-zero area, checked): scale C1 about its area centroid by
// sqrt(area(C2) / area(C1)); move it centroid onto centroid of C2 when that overlaps more; then
// greedy rigid steps: translations by r in eight directions (0, 45, ..., 315 degrees) and
// rotations by ±theta about the moved centroid, taking the move that increases the overlap area
// most, halving r and theta when none does, until r < tolerance * sqrt(area(C2)). r starts at
// 0.1 * sqrt(area(C2)), theta at 10 degrees; at most 2000 rounds. The result is a local maximum
// of the overlap (the search starts from the centroids, so large rotations may not be undone).
// Open curves: the similarity that takes C1's first and last points onto C2's (about the midpoint
// of C1's chord; tolerance is not used). InvalidInput names the argument: non-finite
// coordinates, too few points, zero area (closed), a self-intersecting curve (closed),
// coincident end points (open), a tolerance that is not positive and finite.
Similarity2 align_curves(const Points2Ref& c1, const Points2Ref& c2, bool closed = true, double tolerance = 1e-6);

}  // namespace morphomap
