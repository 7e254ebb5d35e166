#pragma once
// monotone_match without its argument checks, for map_curves' method "optimal": its curves and
// stretch_weight were checked once at map_curves' entry, and the pieces it matches are made of
// those curves' points (in order, finite, at least two each).
#include <morphomap/optimal.hpp>

namespace morphomap::detail {

MonotoneMatch monotone_match_unchecked(const Points2Ref& source, const std::vector<Index>& start_rows,
                                       const Points2Ref& target, double stretch_weight);

}  // namespace morphomap::detail
