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

DisplacementField3 carried_from_coarse(const DisplacementField3& coarse, const Points3Ref& v1, const FacesRef& f1,
                                       const SurfaceIndex& index1, const Points3Ref& v2, const FacesRef& f2,
                                       const SurfaceIndex& index2) {
  // The coarse field read as a piecewise-linear map on c1's triangles, which lie on S1: the same
  // location and interpolation as a reversed field carried onto S1's vertices.
  DisplacementField3 field = carried_onto_source(coarse, v1, f1);
  std::vector<Index> placed;  // the rows with an end (a coarse end may be NaN)
  for (Index i = 0; i < field.size(); ++i) {
    if (field.ends.row(i).allFinite()) placed.push_back(i);
  }
  const SurfaceHits on_target = index2.closest_points(field.ends(placed, Eigen::all));
  for (std::size_t k = 0; k < placed.size(); ++k) field.ends.row(placed[k]) = on_target.points.row(static_cast<Index>(k));
  fill_lost_ends(field, index2);
  unfold(field.starts, field.ends, field.faces, v1, f1, index1, v2, f2, index2);
  return field;
}

}  // namespace morphomap::detail
