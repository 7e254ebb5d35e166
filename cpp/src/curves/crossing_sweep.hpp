#pragma once
// The sweep-line half of crossing_pairs on its own, for the tests: small inputs never reach it
// through crossing_pairs, whose box search answers them first.
#include <morphomap/types.hpp>

#include <utility>
#include <vector>

namespace morphomap::detail {

std::vector<std::pair<Index, Index>> crossing_pairs_by_sweep(const Points2Ref& starts, const Points2Ref& ends);

}  // namespace morphomap::detail
