#pragma once
// solve_diffusion without the curves' and options' checks, for map_curves, which checked its
// curves (require_simple_curve) and options (validate_options) at its entry and calls this on
// the whole pair and on pieces of it. The rules that are diffusion's own (coordinates in range,
// nested or crossing closed curves) still apply here.
#include <morphomap/laplace.hpp>

namespace morphomap::detail {

DiffusionSolution solve_diffusion_unchecked(const Points2Ref& source_points, const Points2Ref& target_points,
                                            bool closed, const DiffusionOptions& options);

}  // namespace morphomap::detail
