#pragma once
// Folded triangles of a 3D field (the test behind count_folds) and their repair.
#include <morphomap/surface_queries.hpp>
#include <morphomap/types.hpp>

#include <vector>

namespace morphomap::detail {

// Per triangle of `faces` (over the rows of starts/ends): 1 where the triangle's orientation
// relative to s1 under its starts differs from that relative to s2 under its ends (count_folds).
std::vector<char> folded_faces(const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces,
                               const Points3Ref& v1, const FacesRef& f1, const SurfaceIndex& index1,
                               const Points3Ref& v2, const FacesRef& f2, const SurfaceIndex& index2);

// Re-places the ends of folded triangles (see unfold.cpp) and returns how many triangles are still
// folded. `ends` must lie on (v2, f2); rows that are NaN stay NaN.
Index unfold(const Points3Ref& starts, Points3& ends, const FacesRef& faces, const Points3Ref& v1, const FacesRef& f1,
             const SurfaceIndex& index1, const Points3Ref& v2, const FacesRef& f2, const SurfaceIndex& index2);

}  // namespace morphomap::detail
