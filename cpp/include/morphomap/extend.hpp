#pragma once
// The displacement inside the domain a boundary encloses, from the displacement field on the
// boundary: what a PDE solver moves the interior nodes of its mesh by (the paper's Figure 1 d-e).
#include <morphomap/field.hpp>
#include <morphomap/types.hpp>

namespace morphomap {

struct InteriorField2 {
  Points2 points;
  Faces cells;                    // triangles
  Points2 displacement;           // at every point
  Index inverted = 0;             // cells turned over (or flattened) by the motion x -> x + u
  double min_jacobian = 0.0;      // smallest ratio of a cell's signed area after and before
  double boundary_distance = 0.0; // farthest boundary node from the source curve (projected)
};

struct InteriorField3 {
  Points3 points;
  Tetrahedra cells;
  Points3 displacement;
  Index inverted = 0;
  double min_jacobian = 0.0;
  double boundary_distance = 0.0;  // farthest boundary node from the start triangles
};

// The harmonic extension: each component of the displacement solves the Laplace equation inside
// (P1 finite elements, sparse LDL^T), equal at the mesh's boundary nodes (those on an edge of one
// triangle only) to the field there (displacement_at: the nodes are projected onto the source
// curve C1, which must be closed). An affine boundary map extends to the same affine map.
// mesh_cells empty: the region C1 encloses is meshed with CGAL's constrained Delaunay mesher,
// every point of C1 a node, edges at most mesh_size (<= 0: graded from C1's point spacing).
// Throws InvalidInput naming "source", "mesh" or "field" (e.g. a boundary node without a
// displacement, where the field missed).
InteriorField2 extend_field(const DisplacementField2& field, const Points2Ref& source, const Points2Ref& mesh_points,
                            const FacesRef& mesh_cells, double mesh_size = 0.0);

// The same in 3D on a tetrahedral mesh (boundary nodes: those on a face of one tetrahedron only),
// the boundary displacement interpolated over the field's start triangles.
InteriorField3 extend_field(const DisplacementField3& field, const Points3Ref& mesh_points,
                            const TetrahedraRef& mesh_cells);

}  // namespace morphomap
