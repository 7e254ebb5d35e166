#pragma once
// Diffusion mapping: the Laplace equation in the region between two curves, and its streamlines.
#include <morphomap/types.hpp>

#include <vector>

namespace morphomap {

struct DiffusionOptions {
  // Mesh size: the lattice spacing is 0.97 times it, and no edge along the curves is longer; in
  // the lattice, a triangle next to a point the mesher added may reach the lattice triangles'
  // circumdiameter (1.12 times it). 0 picks mesh_fraction * the mean gap between the curves
  // (twice the region's area over its boundary length), but no finer than a lattice of
  // max(40000, 20 * the number of curve points) vertices over the region would be; map_curves shares that
  // budget among the pieces it splits a pair into, in proportion to their points (each at least 2000 and
  // 20 per point). Near the curves the mesh is graded from their point spacing and refined where the gap
  // is narrow, whatever this bound.
  double mesh_size = 0.0;
  double mesh_fraction = 0.02;
  bool keep_streamlines = false;
};

struct DiffusionSolution {
  Points2 vertices;                  // the region mesh: every point of both curves is a vertex
  Faces triangles;                   // counter-clockwise
  Vector potential;                  // c at the vertices: P1 finite elements, c = 1 on the source, 0 on the target
  Points2 ends;                      // for each source point, where its streamline of -grad c meets the target
                                     // (NaN if it does not)
  std::vector<Points2> streamlines;  // with keep_streamlines: one polyline per source point
  double mesh_seconds = 0.0, solve_seconds = 0.0, trace_seconds = 0.0;  // where the time went
};

// The region between source and target: closed curves must be nested (an annulus) or cross (each
// lobe of their symmetric difference on its own); open curves are joined start to start and end to
// end by straight edges where c is free (no flux). The mesh: a triangular lattice of spacing
// ~mesh_size inside the region, joined to the curves by CGAL's constrained Delaunay mesher. The P1
// gradient is recovered at the vertices and interpolated linearly (a continuous flow whose
// streamlines do not cross), and each streamline crosses the mesh triangle by triangle in RK4 steps.
DiffusionSolution solve_diffusion(const Points2Ref& source, const Points2Ref& target, bool closed = true,
                                  const DiffusionOptions& options = {});

}  // namespace morphomap
