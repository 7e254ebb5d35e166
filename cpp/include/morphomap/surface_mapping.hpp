#pragma once
// Displacement fields between two closed surfaces (the paper's section "Displacement Fields for
// 3D Objects"): minimal distance, normal and diffusion mapping, reverse, and "auto".
#include <morphomap/field.hpp>
#include <morphomap/mapping.hpp>
#include <morphomap/prepared_surface.hpp>
#include <morphomap/types.hpp>

#include <functional>

namespace morphomap {

struct SurfaceMappingOptions {
  // minimal_distance: each vertex to its closest point on the target.
  // normal: the line through each vertex along its angle-weighted normal, both directions, to the
  //   nearest intersection with the target; NaN where it meets nothing.
  // diffusion: streamlines of Laplace's equation between the surfaces (solve_diffusion_3d); the
  //   ends are put onto their closest point of the target (the tetrahedral mesh only
  //   approximates it).
  // automatic: normal mapping; if it misses anywhere or folds a triangle (count_folds), between
  //   nested surfaces diffusion for the vertices within two mean gaps of those places (the mesh
  //   coarser away from them), its ends blended into the normal ones over the outer gap, the
  //   rest of the normal field kept (methods: normal, diffusion), if that has no fold; else (or
  //   where more than half of the vertices would be redone) reverse diffusion for the whole
  //   surface (rows and faces of the target); where that fails (the region cannot be meshed),
  //   diffusion, then the normal mapping if it missed nothing, then minimal distance.
  // Only the methods kMethodTable marks `surfaces`: uniform, optimal and paper have no 3D form
  // (InvalidInput).
  MapMethod method = MapMethod::normal;
  bool reverse = false;              // map S2 -> S1 and flip: starts on S1, ends on S2, rows and faces of S2
  double diffusion_mesh_size = 0.0;  // ShellDiffusionOptions::mesh_size (0: automatic)
  bool diffusion_repeatable = true;  // ShellDiffusionOptions::repeatable
  // Called with the name of each stage as it begins, on the calling thread (a progress report);
  // may be empty. diffusion: "mesh", "solve", "trace" (ShellDiffusionOptions::on_stage).
  // automatic: "normal", then, if it falls back, those three for each diffusion it tries (local,
  // whole-surface reverse, then forward: they can come up to three times). The other methods
  // report nothing.
  std::function<void(const char* stage)> on_stage;
};

// Both surfaces must pass check_closed_surface (named "s1" and "s2"). Start points are the
// vertices of the source surface (S1, or S2 when reversed), in its order; field.faces are its
// faces. A vector that found nothing keeps its known point: NaN ends on forward vectors, NaN
// starts on reverse ones (methods then name reverse_ variants).
DisplacementField3 map_surfaces(const Points3Ref& v1, const FacesRef& f1, const Points3Ref& v2, const FacesRef& f2,
                                const SurfaceMappingOptions& options = {});

// The same on surfaces checked and indexed once (the same field, bit for bit).
DisplacementField3 map_surfaces(const PreparedSurface& s1, const PreparedSurface& s2,
                                const SurfaceMappingOptions& options = {});

}  // namespace morphomap
