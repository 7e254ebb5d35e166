#pragma once
// Untangling a field's folded triangles on the target surface by a barrier energy: the ends move
// along S2 to lower, per triangle, a regularised distortion that grows without bound as the
// triangle's image shrinks to zero area on S2 — in the limit of the regularisation, the energy of
// a fold-free map (the untangling of Garanzha et al., "Foldover-free maps in 50 lines of code",
// 2021, carried onto a surface). Unlike the area evening (even_surface.hpp), whose energy stays
// finite at zero area, its minimum keeps every image apart from zero area: the voxelised limb
// 270 -> 250 h, whose images are crushed onto S2's cap rim, untangled only so (bench/README.md
// "Real 3D stages").
#include <morphomap/surface_queries.hpp>
#include <morphomap/types.hpp>

#include <optional>
#include <vector>

namespace morphomap::detail {

class FoldTest;

// `ends` (one row per row of `starts`, all finite, on (v2, f2)), the rows not `fixed` moved along
// S2 by rounds of L-BFGS on the regularised energy, the regularisation lowered between rounds as
// Garanzha et al. lower it, until `test` finds no triangle folded (at most `rounds` rounds); each
// image seen in a frame that follows its corners' faces of S2, else, where that does not
// untangle, in one taken once a round with its centroid's face too. alpha =
// area(S2) / area(S1): each triangle's image aims at its start's area times alpha. Returns the
// ends reached once no triangle is folded and every image of a start with area keeps at least
// kLeastImage of it (barrier_untangle.cpp), else none. Polls interrupts.
std::optional<Points3> barrier_untangled(const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces,
                                         const FoldTest& test, const std::vector<char>& fixed, const FacesRef& f2,
                                         const Points3Ref& v2, const SurfaceIndex& index2, double alpha, int rounds);

}  // namespace morphomap::detail
