#pragma once
// A coarse closed surface with poor triangles refined for the mappings that mesh the space
// between two surfaces (diffusion), its own vertices kept where they are.
#include <morphomap/remesh.hpp>
#include <morphomap/types.hpp>

namespace morphomap::detail {

// Whether a closed surface's triangles are too poor for diffusion to trace from its vertices: a
// corner angle below kPoorAngleDegrees (the caps of long thin triangles with which open surfaces
// are closed; surface_from_mask's triangles keep theirs above 20 degrees).
constexpr double kPoorAngleDegrees = 3.0;
bool has_poor_triangles(const Points3Ref& vertices, const FacesRef& faces);

// CGAL's isotropic remeshing at `edge_length` with every input vertex held fixed: the result's
// first rows are the input's vertices, unchanged and in their order; new vertices follow, on the
// input surface. Throws GeometryError where the result would intersect itself.
TriangleSurface refined_keeping_vertices(const Points3Ref& vertices, const FacesRef& faces, double edge_length);

}  // namespace morphomap::detail
