#pragma once
// The public curve functions without their argument checks, for a core that checked its curves
// once at its own entry (map_curves, solve_diffusion, quality) and then calls these many times.
// Each public function is its checks followed by the variant here: every rule has one owner.
// The curves must be what the public function checks for (require_curve; closed ones passed to
// orientation also enclose an area).
#include <morphomap/curve_queries.hpp>
#include <morphomap/types.hpp>

namespace morphomap::detail {

double perimeter_unchecked(const Points2Ref& points, bool closed);
double signed_area_unchecked(const Points2Ref& points);
int orientation_unchecked(const Points2Ref& points);
Points2 normals_unchecked(const Points2Ref& points, bool closed);
CurveIntersections curve_intersections_unchecked(const Points2Ref& c1, const Points2Ref& c2, bool closed);

// CurveIndex over a checked curve, and its queries for finite query points (and, for lines,
// as many non-zero directions as origins).
struct CurveIndexUnchecked {
  static CurveIndex build(const Points2Ref& curve, bool closed);
  static CurveHits closest_points(const CurveIndex& index, const Points2Ref& queries);
  static CurveHits line_intersections(const CurveIndex& index, const Points2Ref& origins, const Points2Ref& directions);
};

}  // namespace morphomap::detail
