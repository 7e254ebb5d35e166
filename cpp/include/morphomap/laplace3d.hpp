#pragma once
// Diffusion mapping in 3D: the Laplace equation in the region between two closed surfaces.
#include <morphomap/types.hpp>

#include <functional>
#include <vector>

namespace morphomap {

struct ShellDiffusionOptions {
  // Largest tetrahedron size (CGAL Mesh_3 cell size); 0: a quarter of the mean gap between the
  // surfaces (the region's volume over the mean of their areas), or in a thin shell, where that
  // is finer than half the surfaces' spacing, half that spacing but at most half the gap. Near
  // each surface the mesh follows its mean edge length (or mesh_size, if smaller), but no finer
  // than 1.5% of the surface's bounding diagonal, and grows away from it by a tenth of the distance.
  double mesh_size = 0.0;
  // true: the same input gives the same mesh, potential and ends, bit for bit, in any process and
  // on any number of threads (Mesh_3 on one core). false: Mesh_3's parallel mode on all cores,
  // faster, but the mesh (and so the ends, within the discretisation error) differs from run to
  // run. Surfaces that cross always mesh repeatably.
  bool repeatable = true;
  bool keep_streamlines = false;
  // Called with "mesh", "solve" and "trace" as each stage begins, on the calling thread (a
  // progress report); may be empty.
  std::function<void(const char* stage)> on_stage;
};

// Wall-clock seconds of the three stages.
struct ShellDiffusionTimings {
  double mesh = 0.0;   // nesting test and Mesh_3
  double solve = 0.0;  // assembly and the sparse solve
  double trace = 0.0;  // locating the starts, streamlines, projection onto the target
};

struct ShellDiffusionSolution {
  Points3 vertices;                  // the tetrahedral mesh of the region (Mesh_3: its boundary approximates
  Tetrahedra tetrahedra;             // the surfaces; input vertices are not mesh vertices); positively oriented
  Vector potential;                  // c at the vertices: P1 finite elements, 1 on the source, 0 on the target
  Points3 ends;                      // for each source vertex, where its streamline of -grad c meets the
                                     // target surface (NaN if it does not)
  std::vector<Points3> streamlines;  // with keep_streamlines: the source vertex, the streamline
                                     // from the mesh boundary, and the end (NaN if lost)
  std::vector<char> touching;        // per source vertex: it touches the target (its end is its
                                     // closest point there, not a streamline's)
  ShellDiffusionTimings seconds;
};

// Both surfaces closed, edge-manifold and consistently oriented (either way round). The region: the
// shell between them when one lies inside the other (which one is found); when they cross, the
// pieces of their symmetric difference (S1 outside S2, S2 outside S1), each bounded by parts of
// both, meshed together with the crossing curves as mesh edges (c = 0 on them). Where the surfaces
// touch or coincide over a patch (as frames contoured on one voxel grid do where the tissue did
// not move), the patch is cut out: source vertices within 1% of the finer mean edge of the target
// map to their closest point there (`touching`), and the source vertices within half that edge
// are pulled back from the target along the source's normals, to half an edge away on the side
// their surroundings lie, before the region is meshed; their streamlines start from there. Such
// a patch whose surroundings lie on both sides of the target (the surfaces also cross there), or
// that the pull-back would fold into itself: InvalidInput. Surfaces that lie apart, only touch
// from outside, or intersect themselves: InvalidInput. Mesh_3 runs in a child process where fork exists
// (it can crash on valid input); a crash there is retried twice with other random choices and
// slightly finer sizes, then a GeometryError. Streamlines start on the
// mesh boundary at the closest point to each source vertex and follow the recovered, linearly
// interpolated -grad c in RK4 steps (in the tetrahedra at a crossing curve, where c jumps, each
// one's own P1 gradient); where one leaves the mesh through the target boundary, its end is moved
// to the closest point of the target surface, and one that runs into a crossing curve ends there.
ShellDiffusionSolution solve_diffusion_3d(const Points3Ref& source_vertices, const FacesRef& source_faces,
                                          const Points3Ref& target_vertices, const FacesRef& target_faces,
                                          const ShellDiffusionOptions& options = {});

}  // namespace morphomap
