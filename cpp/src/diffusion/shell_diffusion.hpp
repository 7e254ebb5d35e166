#pragma once
// solve_diffusion_3d for map_surfaces, which has checked both surfaces, converted them to CGAL's
// form and classified their nesting at its entry (the self-intersection tests are a fifth to a
// third of a 3D step), and holds the target's query index: one conversion, one nesting test and
// one Embree scene of S2 serve the whole call, whichever way round diffusion runs.
#include <morphomap/laplace3d.hpp>
#include <morphomap/surface_queries.hpp>

#include "diffusion/shell_mesh.hpp"

#include <vector>

namespace morphomap::detail {

// A source and a target that passed check_closed_surface with outward faces and require_volume
// (or encloses_volume), as the arrays and
// as their CGAL forms, with their signed volumes, their nesting (classify_nesting(source,
// target), not disjoint) and the target's index (of exactly these arrays).
struct ShellPair {
  Points3Ref source_vertices;
  FacesRef source_faces;
  Points3Ref target_vertices;
  FacesRef target_faces;
  const ClosedSurface& source;
  const ClosedSurface& target;
  double source_volume;
  double target_volume;
  Nesting nesting;
  const SurfaceIndex& target_index;
};

// Diffusion wanted for some source vertices only (auto's local diffusion, nested surfaces): the
// mesh as fine as usual within `radius` of the focus points and coarser away from them
// (ShellMeshCriteria), and only the vertices with traced[i] traced (the other ends NaN).
struct LocalDiffusion {
  Points3 focus;
  double radius = 0.0;
  std::vector<char> traced;
};

// As the public solve_diffusion_3d on a pair checked as above, with options the caller checked;
// with `local`, only that part (surfaces that cross: throws GeometryError).
ShellDiffusionSolution solve_diffusion_3d(const ShellPair& pair, const ShellDiffusionOptions& options,
                                          const LocalDiffusion* local = nullptr);

}  // namespace morphomap::detail
