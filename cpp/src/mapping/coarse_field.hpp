#pragma once
// A field between two large surfaces through coarse copies of them: the copies remeshed evenly
// at a few thousand vertices, mapped there, and the field carried back onto the user's vertices.
// On the voxel-contoured limb stages every whole-resolution candidate of "auto" folds where the
// surfaces cross (its streamlines part over a few of the many small triangles) while the coarse
// copies map fold-free (bench/README.md "Real 3D stages").
#include <morphomap/field.hpp>
#include <morphomap/surface_queries.hpp>
#include <morphomap/types.hpp>

namespace morphomap::detail {

// About how many vertices the coarse copy of S1 has; surfaces of S1 with fewer than twice as many
// are mapped as they are. At 2,500 the limb stages' transferred fields folded more (bench/README.md).
constexpr Index kCoarseVertices = 5000;

// The rounds of isotropic remeshing that make the copies (remesh_surface): 3 took 0.6-1.6 s on the
// limb stages' 63k and 114k faces.
constexpr int kCoarseRemeshing = 3;

// Whether S1 (`v1`) has enough vertices to be mapped through coarse copies.
bool worth_coarsening(const Points3Ref& v1);

// The edge length at which an even remeshing of (v1, f1) has about kCoarseVertices vertices: an
// even mesh of area A and edge h has about 2 A / (sqrt(3) h^2) of them.
double coarse_edge(const Points3Ref& v1, const FacesRef& f1);

// A point carried from the coarse field goes onto S2 along c2's normal there when S2 lies within
// kRayReach times its closest distance that way, else to its closest point. Closest points gather
// the points over a convex crease of a voxel surface onto it, and the thin images there turned:
// 452 folded triangles on the unblurred limb 290 -> 270 h against 101 along the normal
// (bench/README.md "Real 3D stages").
constexpr double kRayReach = 3.0;

// `coarse`: a field of c1's vertices onto c2 (vertices c2, faces g2), c1 and c2 copies of S1
// (v1, f1) and S2 (v2, f2) remeshed onto them. Returns the field of S1's vertices it defines:
// each vertex located on c1's triangles, its end the same barycentric combination of that
// triangle's ends (the piecewise-linear map, carried_onto_source), put on S2 as kRayReach says;
// ends left NaN filled from their neighbours' (fill_lost_ends) and turned triangles repaired
// (unfold). Each row's method is that of the nearest corner of c1.
DisplacementField3 carried_from_coarse(const DisplacementField3& coarse, const Points3Ref& c2, const FacesRef& g2,
                                       const Points3Ref& v1, const FacesRef& f1, const SurfaceIndex& index1,
                                       const Points3Ref& v2, const FacesRef& f2, const SurfaceIndex& index2);

}  // namespace morphomap::detail
