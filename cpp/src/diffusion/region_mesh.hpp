#pragma once
// Triangulation of a planar region bounded by closed loops (CGAL's constrained Delaunay mesher).
#include <morphomap/types.hpp>

#include <vector>

namespace morphomap::detail {

struct RegionMesh {
  Points2 vertices;
  Faces triangles;                // counter-clockwise
  Faces neighbours;               // neighbours(t, i): the triangle across the edge opposite
                                  // vertex i of t, or -1 on the region's boundary
  std::vector<Index> input;       // for each mesh vertex, its input point (loops concatenated), or -1
  std::vector<Index> of_input;    // for each input point, its mesh vertex
  std::vector<char> on_boundary;  // mesh vertex on a constrained (boundary) edge
};

// The loops are closed curves that passed require_curve (their callers' checked curves, or a loop
// made of such curves' points): they are not checked again here.
// The region is the set of points inside an odd number of the loops (an annulus for two nested
// loops, each lobe of the symmetric difference for two crossing ones). Every input point is a
// mesh vertex. With max_edge > 0, the loops' edges are split to at most max_edge and a triangular
// lattice of spacing just under max_edge is seeded inside, a spacing away from the loops. Then
// refinement: Ruppert's angle criterion (smallest angle about 20.7 degrees), which grades the mesh
// from the point spacing on the loops and refines narrow gaps, and edges no longer than max_edge
// (no bound when max_edge <= 0), except in triangles with two lattice vertices and no vertex of
// the loops or of the graded layers: up to a lattice triangle's circumdiameter (1.12 max_edge), so
// that a point the mesher puts among lattice points does not set off splits along a lattice row.
RegionMesh mesh_region(const std::vector<Points2>& loops, double max_edge);

}  // namespace morphomap::detail
