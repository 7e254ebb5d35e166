#pragma once
// A displacement field anywhere on its source boundary: what a PDE solver needs at its own
// boundary nodes, which are not the field's start points.
#include <morphomap/field.hpp>
#include <morphomap/types.hpp>

namespace morphomap {

struct DisplacementAt2 {
  Points2 displacements;  // one row per query point; NaN if the field has no valid vector
  Vector distances;       // from the query point to the boundary it was projected onto
};

struct DisplacementAt3 {
  Points3 displacements;  // NaN where a corner of the triangle found has no target
  Vector distances;
};

// The displacement at `points` of the source curve C1 (`source`, closed or open, as mapped).
// Each point is projected onto C1 (the distance is returned) and placed by arc length among the
// field's valid start points, themselves placed on C1 the same way; the vectors of its two
// neighbours are interpolated linearly in arc length (round the end on a closed curve; before the
// first or after the last start of an open curve, that start's vector). Whatever order the
// field's vectors come in (reverse and crossing fields included), so exact at the start points.
// Throws InvalidInput naming "field", "source" or "points".
DisplacementAt2 displacement_at(const DisplacementField2& field, const Points2Ref& source, bool closed,
                                const Points2Ref& points);

// The displacement at `points` of the source surface: each point is projected onto the field's
// start triangles (field.faces over field.starts; the distance is returned) and the vectors at
// the triangle's corners are interpolated with the barycentric weights of the projection. Exact
// at the start points. Triangles with a corner without a start point are left out.
DisplacementAt3 displacement_at(const DisplacementField3& field, const Points3Ref& points);

}  // namespace morphomap
