#pragma once
// Crossings among a set of segments, such as the vectors of a displacement field.
#include <morphomap/types.hpp>

#include <utility>
#include <vector>

namespace morphomap {

// Pairs (i, j), i < j, of segments starts[i]-ends[i] and starts[j]-ends[j] that have a point in
// common, except pairs whose only common point is an end point of both (vectors that meet at a
// shared start or end). Rows with a non-finite coordinate are skipped. Exact predicates.
std::vector<std::pair<Index, Index>> crossing_pairs(const Points2Ref& starts, const Points2Ref& ends);

// The number of such pairs.
Index count_crossings(const Points2Ref& starts, const Points2Ref& ends);

}  // namespace morphomap
