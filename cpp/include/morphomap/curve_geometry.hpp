#pragma once
// Elementary geometry of one curve: arc length, area, orientation, normals, simplicity.
#include <morphomap/types.hpp>

namespace morphomap {

// Cumulative arc length at each point, starting with 0 at the first point.
Vector arc_lengths(const Points2Ref& points, bool closed = true);

// Total length, including the closing segment of a closed curve.
double perimeter(const Points2Ref& points, bool closed = true);

// Signed area of the closed polygon (shoelace): positive when counter-clockwise.
double signed_area(const Points2Ref& points);

// +1 for a counter-clockwise closed curve, -1 for a clockwise one.
int orientation(const Points2Ref& points);

// Unit normal at each point: the normalised sum of the unit normals of the two segments that meet
// there (one at the ends of an open curve). On a closed curve the normals point outwards whatever
// its orientation; on an open curve they point to the right of the direction of travel.
Points2 normals(const Points2Ref& points, bool closed = true);

// True when two non-adjacent segments of the curve touch or cross (exact predicates).
bool is_self_intersecting(const Points2Ref& points, bool closed = true);

}  // namespace morphomap
