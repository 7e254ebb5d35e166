#pragma once
// Making a 3D field one of S1's vertices, complete where it can be: a field mapped the other way
// round carried onto S1's vertices, and ends a streamline lost filled from its neighbours'.
#include <morphomap/field.hpp>
#include <morphomap/surface_queries.hpp>

#include <vector>

namespace morphomap::detail {

// `reverse`: a field mapped from S2's vertices onto S1, turned round (starts: its points on S1,
// NaN where it found none; ends: S2's vertices; faces: S2's). Returns the field of S1's vertices
// (v1, f1) it defines: each vertex of S1 is located on the image of S2's triangles (the triangles
// whose three corners were mapped), and its end is the point of the same barycentric coordinates
// on S2's triangle, so the end lies on S2 and the map is the piecewise-linear inverse of the
// reverse one. NaN where no image triangle comes within its own longest edge of the vertex (a hole
// of the reverse field). Each row's method is that of the corner nearest to it.
DisplacementField3 carried_onto_source(const DisplacementField3& reverse, const Points3Ref& v1, const FacesRef& f1);

// Fills the NaN ends of `field` (starts: the vertices of the surface with `field.faces`) whose
// vertex is joined through the mesh to a vertex with an end: the harmonic interpolation (uniform
// weights over the mesh's edges) of the known ends, then the closest point of the target
// (`target_index`). Returns how many rows it filled.
Index fill_lost_ends(DisplacementField3& field, const SurfaceIndex& target_index);

// The rows within `rings` edges of a corner of the flagged faces (`faces_flagged`, one per row of
// field.faces), each row once.
std::vector<Index> rows_near(const DisplacementField3& field, const std::vector<char>& faces_flagged, int rings);

}  // namespace morphomap::detail
