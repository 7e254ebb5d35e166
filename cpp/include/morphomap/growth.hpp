#pragma once
// Growth kinematics of a boundary between two times: per segment (2D) or triangle (3D) of the
// boundary, the deformation gradient of the piecewise-linear map from its corners before to its
// corners after, restricted to the boundary, and what biologists report from it (principal
// stretches and directions, areal growth, anisotropy), and the element's velocity split into its
// normal and tangential parts.
#include <morphomap/types.hpp>

namespace morphomap {

using Segments = Eigen::Matrix<Index, Eigen::Dynamic, 2, Eigen::RowMajor>;  // corner pairs
using SegmentsRef = Eigen::Ref<const Segments>;
using Stretches = Eigen::Matrix<double, Eigen::Dynamic, 2, Eigen::RowMajor>;

// Principal directions are reported only where the stretches differ by more than this fraction
// of the larger: a uniform scaling or a rotation has no preferred direction (NaN, not noise).
inline constexpr double kIsotropicTolerance = 1e-6;

struct CurveGrowth {
  Vector stretch;               // per segment: length after / length before
  Points2 direction;            // unit tangent of the segment before (a -> b)
  Vector normal_velocity;       // mean displacement of the two corners / dt, along the outward normal before
  Points2 tangential_velocity;  // the rest of that velocity, along the segment
};

struct SurfaceGrowth {
  Stretches stretches;          // per triangle: principal stretches lambda1 >= lambda2
  Points3 major, minor;         // unit directions in the triangle before that stretch by lambda1,
                                // lambda2 (NaN where isotropic within kIsotropicTolerance)
  Vector normal_velocity;       // mean displacement of the three corners / dt, along the normal before
  Points3 tangential_velocity;  // the rest of that velocity, in the triangle's plane before
};

// `before` and `after`: the same points at two times (a row NaN where the point is not known
// then: its elements are NaN); `segments`: corner pairs (a, b) along the curve. With
// counter_clockwise, the outward normal of a segment with unit tangent t is (t.y, -t.x) (the
// curve runs counter-clockwise round the region), else its opposite. dt > 0.
// Throws InvalidInput naming "after", "segments" or "dt".
CurveGrowth curve_growth(const Points2Ref& before, const Points2Ref& after, const SegmentsRef& segments, double dt,
                         bool counter_clockwise);

// Triangles oriented outwards (their normals (b - a) x (c - a) point out of the region). The map
// of a triangle is F = E' E^+ (E, E' its edge vectors before and after), restricted to the
// triangle's plane before: its singular values are the principal stretches and its right
// singular vectors the principal directions; a degenerate triangle before is NaN throughout.
// Throws InvalidInput naming "after", "faces" or "dt".
SurfaceGrowth surface_growth(const Points3Ref& before, const Points3Ref& after, const FacesRef& faces, double dt);

}  // namespace morphomap
