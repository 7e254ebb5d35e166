#pragma once
// The sweep-line half of crossing_pairs on its own, for the tests (small inputs never reach it
// through crossing_pairs, whose box search answers them first), and a test that stops at the
// first crossing.
#include <morphomap/types.hpp>

#include <utility>
#include <vector>

namespace morphomap::detail {

std::vector<std::pair<Index, Index>> crossing_pairs_by_sweep(const Points2Ref& starts, const Points2Ref& ends);

// Whether any pair crosses (count_crossings > 0), by the sweep alone, stopping at the first: the
// default ranks only crossing-free candidates, and counting exactly (the box search's millions of
// overlapping pairs on a crossing-free field of 10^4 long vectors, or a normal mapping's hundreds
// of thousands of crossings) was a fifth of its time at 10^4 points (bench/README.md "Real 2D
// outlines").
bool any_crossing(const Points2Ref& starts, const Points2Ref& ends);

}  // namespace morphomap::detail
