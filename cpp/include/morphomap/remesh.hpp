#pragma once
// Near-uniform triangles on a closed surface, such as one contoured from a voxel mask.
#include <morphomap/types.hpp>

namespace morphomap {

struct TriangleSurface {
  Points3 vertices;
  Faces faces;
};

// The same closed surface with triangles of edge length about `edge_length` (CGAL's isotropic
// remeshing: edge splits, collapses, flips and tangential relaxation, every new vertex projected
// back onto the input surface). The input must be a closed, consistently oriented manifold
// triangle mesh in one piece; it may hold the slivers and zero-area faces of marching cubes,
// which are removed first. The orientation is kept. `iterations` >= 1 remeshing rounds. The
// result does not intersect itself: spots where remeshing turned triangles over are repaired
// (CGAL's remove_self_intersections), and GeometryError is thrown if that fails.
// Throws InvalidInput naming "surface", "edge_length" or "iterations".
TriangleSurface remesh_surface(const Points3Ref& vertices, const FacesRef& faces, double edge_length,
                               int iterations = 5);

}  // namespace morphomap
