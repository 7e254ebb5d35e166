#pragma once
// The last resort of "auto" in 3D (surface_mapping.cpp): a complete field's folds turned back by
// the descent of 3D "optimal" over the ends around them, else by the barrier untangling of every end.
#include <morphomap/field.hpp>
#include <morphomap/surface_queries.hpp>
#include <morphomap/types.hpp>

#include "mapping/coarse_field.hpp"

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
// Where that leaves folds, every end moves along S2 by barrier_untangled (barrier_untangle.hpp),
// at most kBarrierRounds rounds, on fields of at most kBarrierEnds vertices: every S1 that "auto"
// does not map through coarse copies, and the copies themselves. The voxelised limb 270 -> 250 h
// folds where 270's flat cap overhangs 250's, crushed onto its rim over a band wider than the
// rings around the folds: held there, the ends around them could not make room, and the copies'
// field untangled only with every end free (bench/README.md "Real 3D stages").
constexpr int kBarrierRounds = 30;
constexpr Index kBarrierEnds = 2 * kCoarseVertices;

// `field`: complete, of S1's vertices (v1, f1) onto S2 (v2, f2); `test` its fold test.
std::optional<DisplacementField3> untangled(DisplacementField3 field, const FoldTest& test, const Points3Ref& v1,
                                            const FacesRef& f1, const SurfaceIndex& index1, const Points3Ref& v2,
                                            const FacesRef& f2, const SurfaceIndex& index2);

}  // namespace morphomap::detail
