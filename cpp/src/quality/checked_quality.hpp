#pragma once
// quality of a 2D field after its checks, for the callers inside the library that have checked
// the curves and built their indexes already.
#include <morphomap/curve_queries.hpp>
#include <morphomap/quality.hpp>

namespace morphomap::detail {

// c1 and c2 passed require_curve, index1 and index2 are built from them as given. Without
// with_crossings, `crossings` is left 0: the default ranks candidates it has already found
// crossing-free, and an exact count of a crossing-free field of 10^4 vectors tests every pair of
// overlapping vectors (bench/README.md, "Real 2D outlines").
CurveQuality checked_quality(const DisplacementField2& field, const Points2Ref& c1, const CurveIndex& index1,
                             const Points2Ref& c2, const CurveIndex& index2, bool closed, bool with_crossings = true);

}  // namespace morphomap::detail
