#pragma once
// The trace stage of 3D diffusion: streamlines of -grad c from the source boundary of the mesh to
// its target boundary, and the exit of each source vertex (shell_tracer.cpp).
#include <morphomap/types.hpp>

#include "diffusion/shell_diffusion.hpp"
#include "diffusion/shell_mesh.hpp"

#include <Eigen/Core>

#include <vector>

namespace morphomap::detail {

struct ShellExits {
  Points3 exits;  // per source vertex: where its streamline leaves the mesh through the target, or NaN
  std::vector<std::vector<Eigen::Vector3d>> paths;  // with keep_streamlines: each streamline, else none
};

// The exits of the source vertices (all of them, or those `local` traces; the others NaN) on the
// solved mesh: `potential` is c at its vertices, `kind` each vertex's Dirichlet kind (dirichlet.hpp),
// `source_facets` its faces on the source (tetrahedron * 4 + face), `source_region` the source as
// meshed (contact3d.hpp's cleared vertices). With `keep_streamlines` each vertex is traced itself
// and its path kept (starting at its vertex of `source_vertices`); otherwise the exits are
// interpolated from the streamlines of the facets' corners.
ShellExits trace_exits(const ShellMesh& mesh, const Vector& potential, const std::vector<char>& kind,
                       const std::vector<Index>& source_facets, const Points3Ref& source_vertices,
                       const Points3& source_region, const LocalDiffusion* local, bool keep_streamlines);

}  // namespace morphomap::detail
