#pragma once
// Folded triangles of a 3D field (the test behind count_folds) and their repair.
#include <morphomap/surface_queries.hpp>
#include <morphomap/types.hpp>

#include <vector>

namespace morphomap::detail {

// The fold test: a triangle of `faces` (over the rows of starts/ends) is folded where its
// orientation relative to s1 under its starts differs from that relative to s2 under its ends.
// The start side is computed once, so that a repair moving ends can retest the triangles it moved.
// The arrays viewed and the index must outlive the test.
class FoldTest {
 public:
  FoldTest(const Points3Ref& starts, const FacesRef& faces, const Points3Ref& v1, const FacesRef& f1,
           const SurfaceIndex& index1, const Points3Ref& v2, const FacesRef& f2, const SurfaceIndex& index2);

  // For each of `triangles` (rows of faces): the cosine between the normal of its image under
  // `ends` and s2's normal under it, signed by its orientation on s1. Negative where folded, 0
  // where either side is flat, NaN where a corner has no start or no end.
  std::vector<double> agreement(const Points3Ref& ends, const std::vector<Index>& triangles) const;

  // 1 per row of faces where folded (agreement < 0).
  std::vector<char> folded(const Points3Ref& ends) const;

 private:
  Points3Ref starts_;
  FacesRef faces_;
  Points3Ref v2_;
  FacesRef f2_;
  const SurfaceIndex& index2_;
  std::vector<signed char> start_sign_;  // per face: the sign of its orientation on s1 (0 if unknown)
};

// Re-places the ends of folded triangles (see unfold.cpp) and returns how many triangles are still
// folded. `ends` must lie on (v2, f2); rows that are NaN stay NaN.
Index unfold(const Points3Ref& starts, Points3& ends, const FacesRef& faces, const Points3Ref& v1, const FacesRef& f1,
             const SurfaceIndex& index1, const Points3Ref& v2, const FacesRef& f2, const SurfaceIndex& index2);

}  // namespace morphomap::detail
