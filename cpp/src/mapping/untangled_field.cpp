// The last resort of "auto" in 3D (untangled_field.hpp).
#include "mapping/untangled_field.hpp"

#include "mapping/barrier_untangle.hpp"
#include "mapping/even_surface.hpp"
#include "mapping/surface_fields.hpp"
#include "quality/folds.hpp"
#include "surfaces/surface_util.hpp"

#include <algorithm>
#include <utility>
#include <vector>

namespace morphomap::detail {

namespace {

// The ends around the folds evened along S2 (untangled_field.hpp), the others held; none where
// they are too many or folds remain.
std::optional<DisplacementField3> evened_near_folds(DisplacementField3 field, const FoldTest& test,
                                                    const Points3Ref& v1, const FacesRef& f1,
                                                    const SurfaceIndex& index1, const Points3Ref& v2,
                                                    const FacesRef& f2, const SurfaceIndex& index2) {
  const FacesRef faces = field.faces;
  // The ends that move: the folded triangles' corners and kUntangleRings rings around them.
  const std::vector<Index> moving = rows_near(field, test.folded(field.ends), kUntangleRings);
  if (static_cast<Index>(moving.size()) > kUntangleEnds) return std::nullopt;
  std::vector<char> free(static_cast<std::size_t>(field.size()), 0);
  for (const Index v : moving) free[static_cast<std::size_t>(v)] = 1;
  // The triangles touching them, over their own numbering of the ends.
  std::vector<Index> local(static_cast<std::size_t>(field.size()), -1), rows;
  std::vector<Index> kept;
  for (Index f = 0; f < faces.rows(); ++f) {
    if (!(free[static_cast<std::size_t>(faces(f, 0))] || free[static_cast<std::size_t>(faces(f, 1))] ||
          free[static_cast<std::size_t>(faces(f, 2))]))
      continue;
    kept.push_back(f);
    for (int i = 0; i < 3; ++i) {
      Index& at = local[static_cast<std::size_t>(faces(f, i))];
      if (at < 0) at = static_cast<Index>(rows.size()), rows.push_back(faces(f, i));
    }
  }
  const Index count = static_cast<Index>(rows.size());
  Points3 starts(count, 3), ends(count, 3);
  Faces part(static_cast<Index>(kept.size()), 3);
  EvenOptions options;
  options.until_unfolded = true;
  options.max_iterations = kUntangleSteps;
  options.fixed.resize(static_cast<std::size_t>(count));
  for (Index k = 0; k < count; ++k) {
    starts.row(k) = field.starts.row(rows[static_cast<std::size_t>(k)]);
    ends.row(k) = field.ends.row(rows[static_cast<std::size_t>(k)]);
    options.fixed[static_cast<std::size_t>(k)] =
        free[static_cast<std::size_t>(rows[static_cast<std::size_t>(k)])] ? 0 : 1;
  }
  for (std::size_t k = 0; k < kept.size(); ++k) {
    for (int i = 0; i < 3; ++i) part(static_cast<Index>(k), i) = local[static_cast<std::size_t>(faces(kept[k], i))];
  }
  const FoldTest part_test(starts, part, v1, f1, index1, v2, f2, index2);
  const double alpha = area_factor(v1, f1, v2, f2);
  const Points3 moved = even_ends(starts, ends, part, part_test, v2, f2, index2, alpha, options);
  for (Index k = 0; k < count; ++k) field.ends.row(rows[static_cast<std::size_t>(k)]) = moved.row(k);
  const std::vector<char> folded = test.folded(field.ends);
  if (std::find(folded.begin(), folded.end(), 1) != folded.end()) return std::nullopt;
  for (const Index v : moving) field.methods[static_cast<std::size_t>(v)] = Method::optimal;
  return field;
}

}  // namespace

std::optional<DisplacementField3> untangled(DisplacementField3 field, const FoldTest& test, const Points3Ref& v1,
                                            const FacesRef& f1, const SurfaceIndex& index1, const Points3Ref& v2,
                                            const FacesRef& f2, const SurfaceIndex& index2) {
  if (std::optional<DisplacementField3> evened = evened_near_folds(field, test, v1, f1, index1, v2, f2, index2))
    return evened;
  if (field.size() > kBarrierEnds) return std::nullopt;
  const std::vector<char> none(static_cast<std::size_t>(field.size()), 0);
  std::optional<Points3> ends = barrier_untangled(field.starts, field.ends, field.faces, test, none, f2, v2, index2,
                                                  area_factor(v1, f1, v2, f2), kBarrierRounds);
  if (!ends) return std::nullopt;
  field.ends = std::move(*ends);
  std::fill(field.methods.begin(), field.methods.end(), Method::optimal);
  return field;
}

}  // namespace morphomap::detail
