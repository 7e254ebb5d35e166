#pragma once
// The last resort of "auto" in 3D (surface_mapping.cpp): a complete field's folds turned back by
// the descent of 3D "optimal" over the ends around them.
#include <morphomap/field.hpp>
#include <morphomap/surface_queries.hpp>
#include <morphomap/types.hpp>

#include <optional>

namespace morphomap::detail {

class FoldTest;

// The last resort of "auto": a complete candidate's ends around its folded triangles (within
// kUntangleRings edges of them) moved along S2 by even_ends, which turns folded triangles back
// while it evens the areas, the ends beyond held; kept only where no triangle is left folded (limb
// bud 290 -> 250 h: every candidate folds 2-20 triangles at the tip; bench/README.md "Real 3D
// stages"). The vectors moved are labelled optimal. Each step costs a sparse factorisation over the
// ends that move: at most kUntangleEnds of them and kUntangleSteps steps, else refused (a
// voxelised stage's thousands of folds took minutes to refuse).
constexpr int kUntangleRings = 10;
constexpr Index kUntangleEnds = 5000;
constexpr int kUntangleSteps = 40;

// `field`: complete, of S1's vertices (v1, f1) onto S2 (v2, f2); `test` its fold test.
std::optional<DisplacementField3> untangled(DisplacementField3 field, const FoldTest& test, const Points3Ref& v1,
                                            const FacesRef& f1, const SurfaceIndex& index1, const Points3Ref& v2,
                                            const FacesRef& f2, const SurfaceIndex& index2);

}  // namespace morphomap::detail
