#pragma once
// The displacement inside the domain a boundary encloses, from the displacement field on the
// boundary: what a PDE solver moves the interior nodes of its mesh by (the paper's Figure 1 d-e).
#include <morphomap/field.hpp>
#include <morphomap/types.hpp>

namespace morphomap {

struct InteriorField2 {
  Points2 points;
  Faces cells;                     // triangles
  Points2 displacement;            // at every point
  Index inverted = 0;              // cells turned over (or flattened) by the motion x -> x + u
  double min_jacobian = 0.0;       // smallest ratio of a cell's signed area after and before
  double boundary_distance = 0.0;  // farthest boundary node from the source curve (projected)
};

struct InteriorField3 {
  Points3 points;
  Tetrahedra cells;
  Points3 displacement;
  Index inverted = 0;
  double min_jacobian = 0.0;
  double boundary_distance = 0.0;  // farthest boundary node from the start triangles
};

enum class ExtensionMethod {
  harmonic,  // each component solves the Laplace equation
  elastic,   // the displacement solves linear elasticity (isotropic, the given Poisson ratio)
};

struct ExtendOptions {
  ExtensionMethod method = ExtensionMethod::harmonic;
  double poisson_ratio = 0.3;  // elastic: 0 <= nu < 0.5 (Young's modulus cancels out)
  // The motion in `substeps` equal steps of the boundary displacement, each solved on the mesh as
  // the steps before have moved it (1: one solve on the mesh as given). Large growth steps invert
  // cells under one solve; re-solving on the moving mesh lets the interior follow the boundary.
  int substeps = 1;
  // After the solve(s), move the free corners of the cells still inverted, each to the point that
  // maximises the smallest area (volume) ratio of its cells (a small linear program per node, in
  // sweeps until none is inverted or nothing moves). Those nodes' displacement is then no longer
  // the method's solution; cells with all corners on the boundary cannot be untangled this way.
  bool untangle = false;
  // No mesh given: the largest edge of the mesh made (0: graded from the boundary's spacing); >= 0.
  double mesh_size = 0.0;
  int seed = 0;  // 3D without a mesh: of Mesh_3's random choices (the same seed, the same mesh)
};

// The extension: the displacement at the mesh's boundary nodes (those on an edge of one triangle
// or a face of one tetrahedron only) is the field there (displacement_at: 2D nodes are projected
// onto the source curve C1, which must be closed; 3D nodes onto the field's start triangles), and
// inside it solves the method's equations (P1 finite elements, multifrontal sparse Cholesky in 2D, conjugate
// gradients first in 3D). Either method extends an affine boundary map to the same affine map.
// 2D, mesh_cells empty: the region C1 encloses is meshed with CGAL's constrained Delaunay mesher,
// every point of C1 a node, edges at most mesh_size (0: graded from C1's point spacing); a
// triangle with its three corners on C1 (which would move with the boundary field alone) is
// split at the midpoint of its longest inner edge.
// 3D, mesh_cells empty: the region the start triangles enclose (a closed surface) is meshed with
// CGAL's Mesh_3 (its surface nodes lie on the triangles; a tetrahedron with all four corners on
// them, which would move with the boundary field alone, gets a node inside by a split of its
// longest inner edge, unless all six of its edges lie on the surface).
// Throws InvalidInput naming "source", "mesh", "field", "poisson_ratio", "substeps" or
// "mesh_size" (e.g. a boundary node without a displacement, where the field missed).
InteriorField2 extend_field(const DisplacementField2& field, const Points2Ref& source, const Points2Ref& mesh_points,
                            const FacesRef& mesh_cells, const ExtendOptions& options = {});

InteriorField3 extend_field(const DisplacementField3& field, const Points3Ref& mesh_points,
                            const TetrahedraRef& mesh_cells, const ExtendOptions& options = {});

}  // namespace morphomap
