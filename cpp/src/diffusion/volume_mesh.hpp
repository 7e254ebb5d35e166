#pragma once
// The region one closed surface encloses as tetrahedra (CGAL's Mesh_3): the default mesh of the
// 3D interior displacement. Kept small: the translation unit behind it compiles for minutes.
#include <morphomap/types.hpp>

namespace morphomap::detail {

struct VolumeMesh {
  Points3 vertices;       // those on the boundary lie on the surface's triangles
  Tetrahedra tetrahedra;  // positively oriented
};

// The surface: closed, manifold, free of self-intersections (else InvalidInput naming
// `name`). Edges and surface triangles about `size` long; `seed` fixes Mesh_3's random choices
// (the same seed, the same mesh). A tetrahedron with four corners on the surface has its longest
// edge through the inside (chord) split at the midpoint, so that it gets a free node; one whose six
// edges all lie on the surface (possible only where the surface folds sharply) is left whole.
// Runs in a child process (mesh_in_child.hpp): a crash of CGAL becomes a GeometryError. Throws GeometryError if Mesh_3
// gives no tetrahedra.
VolumeMesh mesh_volume(const Points3Ref& vertices, const FacesRef& faces, double size, int seed, const char* name);

}  // namespace morphomap::detail
