#pragma once
// "auto" where normal mapping folds or misses on part of the surface only: the normal field kept
// elsewhere, diffusion near that part, blended into the normal field across a band.
#include <morphomap/field.hpp>
#include <morphomap/laplace3d.hpp>
#include <morphomap/surface_queries.hpp>

#include "diffusion/shell_diffusion.hpp"

#include <optional>
#include <vector>

namespace morphomap::detail {

// `normal`: normal mapping of pair (nested surfaces) from S1's vertices, with S1's faces, that
// folds or misses somewhere; `folded`: FoldTest's flags of its faces. Returns a field with every vertex mapped and no
// fold, or nothing where this way gives none (too much of S1 to redo, a lost streamline, folds left at the seam): the
// caller then maps the whole surface another way.
std::optional<DisplacementField3> normal_with_local_diffusion(const DisplacementField3& normal,
                                                              const std::vector<char>& folded, const ShellPair& pair,
                                                              const SurfaceIndex& source_index,
                                                              const ShellDiffusionOptions& options);

}  // namespace morphomap::detail
