#pragma once
// 3D "optimal": a fold-free, complete field's ends moved along the target surface until the map
// of each triangle changes its area by the same factor (see even_surface.cpp).
#include <morphomap/surface_queries.hpp>
#include <morphomap/types.hpp>

namespace morphomap::detail {

class FoldTest;

struct EvenOptions {
  int max_iterations = 400;
  // Stop once an iteration lowers the energy by less than this fraction of it.
  double tolerance = 1e-6;
};

// `ends` (one row per row of `starts`, all finite, on (v2, f2), no triangle of `faces` folded by
// `test`) moved along (v2, f2) to lower sum_j (A'_j / (alpha A_j) - 1)^2 over the triangles
// (A_j, A'_j their areas before and after, alpha = area(S2) / area(S1)): QM1 of the 3D quality
// measure. Each step never folds a triangle and leaves every end on S2. Polls interrupts.
Points3 even_ends(const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces, const FoldTest& test,
                  const Points3Ref& v2, const FacesRef& f2, const SurfaceIndex& index2, double alpha,
                  const EvenOptions& options = {});

}  // namespace morphomap::detail
