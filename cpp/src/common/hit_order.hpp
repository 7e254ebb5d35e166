#pragma once
// The order of line hits that curve_queries.hpp and surface_queries.hpp promise: nearer the
// origin first, then the positive side, then the lower segment or face index.
#include <cmath>
#include <cstdint>

namespace morphomap::detail {

// Whether a hit at signed distance t on element `id` comes before the best so far.
inline bool line_hit_before(double t, std::int64_t id, double best_t, std::int64_t best_id) {
  const double at = std::abs(t), ab = std::abs(best_t);
  if (at != ab) return at < ab;
  if ((t < 0) != (best_t < 0)) return t >= 0;
  return id < best_id;
}

}  // namespace morphomap::detail
