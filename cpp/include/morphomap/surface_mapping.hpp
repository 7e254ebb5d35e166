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
  //   approximates it). A lost streamline takes the harmonic interpolation of its neighbours'
  //   ends, put on the target. A surface with a corner angle below 3 degrees (the flat caps of
  //   long thin triangles that close open surfaces) is refined for diffusion by isotropic
  //   remeshing with its vertices held; the field is reported on its own vertices.
  // automatic (the default): every vertex of S1 mapped and no triangle folded (count_folds), or
  //   GeometryError naming, for each way tried, how many vertices it left unmapped and how many
  //   triangles folded, and where. Tried in turn: normal mapping; between nested surfaces, the
  //   normal field with diffusion within two mean gaps of where it failed; where S1 has more than
  //   10,000 vertices, automatic on copies of both remeshed to about 5,000 vertices of S1, its
  //   field carried back onto S1's vertices; reverse diffusion carried onto S1's vertices and
  //   diffusion (forward first where S2 has fewer vertices; each with the ends around its last
  //   folds re-placed by harmonic interpolation where that removes them); minimal distance;
  //   reverse normal mapping and reverse minimal distance, carried (not after the coarse
  //   copies, whose candidates include them). The complete field with the fewest folds so far
  //   has the ends around its folds moved along S2 until they unfold (after the coarse copies,
  //   after the diffusions, and at the end), where that succeeds. Reversed, the same ways from
  //   S2 without the coarse copies, each carried onto S1 and judged there.
  // optimal: auto's field, then its ends moved along S2 so that every triangle's image keeps its
  //   share of S2's area (the sum of (A'/(alpha A) - 1)^2 over the triangles, QM1 of the 3D quality
  //   measure, lowered in steps that fold no triangle and keep every end on S2); every vector
  //   labelled optimal. The radial map between concentric spheres is its minimum.
  // Only the methods kMethodTable marks `surfaces`: uniform and paper have no 3D form
  // (InvalidInput).
  MapMethod method = MapMethod::automatic;
  // Map S2 -> S1, then carry that field onto S1's vertices: each vertex located on the image of
  // S2's triangles, its end the point of S2's triangle with the same barycentric coordinates.
  bool reverse = false;
  double diffusion_mesh_size = 0.0;  // ShellDiffusionOptions::mesh_size (0: automatic)
  bool diffusion_repeatable = true;  // ShellDiffusionOptions::repeatable
  // Called with the name of each stage as it begins, on the calling thread (a progress report);
  // may be empty. diffusion: "mesh", "solve", "trace" (ShellDiffusionOptions::on_stage).
  // automatic: "normal", then, if it falls back, those three for each diffusion it tries (local,
  // reverse, then forward: they can come up to three times). optimal: auto's, then "optimal".
  // The other methods report nothing.
  std::function<void(const char* stage)> on_stage;
};

// Both surfaces must pass check_closed_surface (named "s1" and "s2"). Every method, either way
// round, returns one vector per vertex of S1, in its order, with S1's faces; a vertex that found
// nothing has NaN ends (methods name reverse_ variants when reversed).
DisplacementField3 map_surfaces(const Points3Ref& v1, const FacesRef& f1, const Points3Ref& v2, const FacesRef& f2,
                                const SurfaceMappingOptions& options = {});

// The same on surfaces checked and indexed once (the same field, bit for bit).
DisplacementField3 map_surfaces(const PreparedSurface& s1, const PreparedSurface& s2,
                                const SurfaceMappingOptions& options = {});

}  // namespace morphomap
