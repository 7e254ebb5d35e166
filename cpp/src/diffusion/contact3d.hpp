#pragma once
// Contact between two closed surfaces for 3D diffusion: where frames contoured on one voxel grid
// share or nearly share faces (the tissue did not move there), the region between the surfaces
// has no volume, and Mesh_3 refuses it, crashes or spends minutes on the sliver. As 2D splits the
// curves at a contact stretch, 3D cuts such a patch out of the problem: its vertices map to their
// closest point on the target, and the source is pulled back from the target there by a small
// clearance so that the rest of the region between the surfaces can be meshed and solved.
#include <morphomap/surface_queries.hpp>
#include <morphomap/types.hpp>

#include "diffusion/shell_mesh.hpp"

#include <vector>

namespace morphomap::detail {

struct ClearedSource {
  Points3 vertices;            // the source, its vertices near the target pulled back
  std::vector<char> touching;  // per source vertex: within the contact tolerance of the target
  Points3 closest;             // per source vertex within the clearance or the tolerance: its closest
                               // point on the target (NaN further away)
  Index moved = 0;             // how many vertices were pulled back
  double near_area = 0.0;      // of the source faces whose corners all lie within the clearance
};

// Source and target closed and outward-oriented; `target_surface` and `target_index` built from
// the target. Every
// connected patch of source vertices closer than `clearance` to the target is pulled back along
// the source's normals until it lies about `clearance` from the target, on the side of the target
// where the patch's surroundings (its ring of farther vertices) lie. A patch whose surroundings lie
// on both sides (it touches where the surfaces also cross) is left to the crossing region, its
// vertices within `tolerance` of the target lifted off by `tolerance`, unless it has a face
// within `tolerance` at all three corners: then, as for a surface that lies within `clearance`
// everywhere, InvalidInput.
ClearedSource clear_contact(const Points3Ref& source_vertices, const FacesRef& source_faces,
                            const Points3Ref& target_vertices, const FacesRef& target_faces,
                            const ClosedSurface& target_surface, const SurfaceIndex& target_index, double clearance,
                            double tolerance);

}  // namespace morphomap::detail
