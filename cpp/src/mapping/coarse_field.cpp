// A field between two large surfaces through coarse copies of them (coarse_field.hpp).
#include "mapping/coarse_field.hpp"

#include "mapping/surface_fields.hpp"
#include "quality/folds.hpp"
#include "surfaces/surface_util.hpp"

#include <cmath>
#include <vector>

namespace morphomap::detail {

bool worth_coarsening(const Points3Ref& v1) { return v1.rows() > 2 * kCoarseVertices; }

double coarse_edge(const Points3Ref& v1, const FacesRef& f1) {
  return std::sqrt(2.0 * surface_area(v1, f1) / (std::sqrt(3.0) * static_cast<double>(kCoarseVertices)));
}

DisplacementField3 carried_from_coarse(const DisplacementField3& coarse, const Points3Ref& c2, const FacesRef& g2,
                                       const Points3Ref& v1, const FacesRef& f1, const SurfaceIndex& index1,
                                       const Points3Ref& v2, const FacesRef& f2, const SurfaceIndex& index2) {
  // The coarse field read as a piecewise-linear map on c1's triangles, which lie on S1: the same
  // location and interpolation as a reversed field carried onto S1's vertices.
  DisplacementField3 field = carried_onto_source(coarse, v1, f1);
  std::vector<Index> placed;  // the rows with an end (a coarse end may be NaN)
  for (Index i = 0; i < field.size(); ++i) {
    if (field.ends.row(i).allFinite()) placed.push_back(i);
  }
  const Points3 near = field.ends(placed, Eigen::all);
  // c2's normal at each point, interpolated from its vertex normals.
  const SurfaceHits on_coarse = SurfaceIndex(c2, g2).closest_points(near);
  const Points3 normals = vertex_normals(c2, g2);
  Points3 directions(near.rows(), 3);
  for (Index k = 0; k < near.rows(); ++k) {
    const Index face = on_coarse.faces[k];
    const V3 b = barycentric(corner(c2, g2, face, 0), corner(c2, g2, face, 1), corner(c2, g2, face, 2),
                             on_coarse.points.row(k).transpose());
    directions.row(k) =
        b[0] * normals.row(g2(face, 0)) + b[1] * normals.row(g2(face, 1)) + b[2] * normals.row(g2(face, 2));
  }
  const SurfaceHits closest = index2.closest_points(near);
  const SurfaceHits along = index2.line_intersections(near, directions);
  for (std::size_t k = 0; k < placed.size(); ++k) {
    const Index row = static_cast<Index>(k);
    const bool hit =
        std::isfinite(along.distances[row]) && std::abs(along.distances[row]) <= kRayReach * closest.distances[row];
    field.ends.row(placed[k]) = hit ? along.points.row(row) : closest.points.row(row);
  }
  fill_lost_ends(field, index2);
  unfold(field.starts, field.ends, field.faces, v1, f1, index1, v2, f2, index2);
  return field;
}

}  // namespace morphomap::detail
