#pragma once
// solve_diffusion_3d for callers that already hold the target's query index (map_surfaces), so
// that one Embree scene of S2 serves the mapping, the diffusion's end points and the fold repair.
#include <morphomap/laplace3d.hpp>
#include <morphomap/surface_queries.hpp>

namespace morphomap::detail {

// As the public solve_diffusion_3d; `target_index`, when given, must index exactly
// (target_vertices, target_faces); null: built here, after the surfaces are checked.
ShellDiffusionSolution solve_diffusion_3d(const Points3Ref& source_vertices, const FacesRef& source_faces,
                                          const Points3Ref& target_vertices, const FacesRef& target_faces,
                                          const ShellDiffusionOptions& options, const SurfaceIndex* target_index);

}  // namespace morphomap::detail
