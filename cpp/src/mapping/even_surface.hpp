#pragma once
// 3D "optimal": a fold-free, complete field's ends moved along the target surface until the map
// of each triangle changes its area by the same factor (see even_surface.cpp).
#include <morphomap/surface_queries.hpp>
#include <morphomap/types.hpp>

#include <vector>

namespace morphomap::detail {

class FoldTest;

struct EvenOptions {
  int max_iterations = 400;
  // Stop once ten iterations together lower the energy by less than this fraction of it.
  double tolerance = 0.05;
  // Stop at the first step after which no triangle is folded (to untangle, not to even).
  bool until_unfolded = false;
  // Per end, 1 where it stays where it is (empty: every end moves).
  std::vector<char> fixed;
};

// `ends` (one row per row of `starts`, all finite, on (v2, f2)) moved along (v2, f2) to lower
// sum_j (A'_j / (alpha A_j) - 1)^2 over the triangles (A_j, A'_j their areas before and after,
// alpha = area(S2) / area(S1)): QM1 of the 3D quality measure. A triangle folded by `test` counts
// its ratio negative, so the descent turns it back; no step folds a triangle that was not folded at
// the start, and every end stays on S2. Polls interrupts.
Points3 even_ends(const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces, const FoldTest& test,
                  const Points3Ref& v2, const FacesRef& f2, const SurfaceIndex& index2, double alpha,
                  const EvenOptions& options = {});

}  // namespace morphomap::detail
