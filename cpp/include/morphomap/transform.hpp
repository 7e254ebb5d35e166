#pragma once
// The paper's Appendix A: a similarity transformation that brings C1 close to C2 before mapping.
#include <morphomap/types.hpp>

namespace morphomap {

// x -> centre + translation + scale * R(angle) * (x - centre)
struct Similarity2 {
  Vec2 centre = Vec2::Zero();
  double scale = 1.0;
  double angle = 0.0;  // radians, counter-clockwise
  Vec2 translation = Vec2::Zero();

  Points2 apply(const Points2Ref& points) const;
  Points2 apply_inverse(const Points2Ref& points) const;
};

// Area of the intersection of the regions enclosed by two closed curves (each simple), from the
// exact crossings of their boundaries.
double overlap_area(const Points2Ref& a, const Points2Ref& b);

// Closed curves: scale C1 about its centroid to the area of C2, then greedy rigid steps
// (translations in eight directions, rotations both ways) that increase the overlap area, halving
// the steps when none helps, until the translation step falls below tolerance * size of C2.
// Open curves: the similarity that takes C1's end points onto C2's.
Similarity2 align_curves(const Points2Ref& c1, const Points2Ref& c2, bool closed = true,
                         double tolerance = 1e-6);

}  // namespace morphomap
