#pragma once
// The mesh that 3D diffusion solves on: the source cleared of its contact with the target
// (contact3d.hpp), the element sizes chosen from the surfaces' spacing, size and gap, and the
// region between them meshed by Mesh_3 in a child process (shell_mesh.hpp, mesh_in_child.hpp).
#include <morphomap/laplace3d.hpp>

#include "diffusion/contact3d.hpp"
#include "diffusion/shell_diffusion.hpp"
#include "diffusion/shell_mesh.hpp"

namespace morphomap::detail {

struct ShellRegion {
  ShellMesh mesh;
  ClearedSource cleared;  // the source as meshed, and which of its vertices touch the target
};

// For solve_diffusion_3d(pair, options, local) (shell_diffusion.hpp). InvalidInput where the
// surfaces only touch from outside or their contact cannot be cleared; GeometryError where the
// mesher keeps crashing, or for `local` on crossing surfaces.
ShellRegion mesh_shell_region(const ShellPair& pair, const ShellDiffusionOptions& options, const LocalDiffusion* local);

}  // namespace morphomap::detail
