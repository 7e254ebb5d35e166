#pragma once
// Whether a point lies inside a closed polygon (even-odd rule): for curves known not to cross,
// where one point of a curve tells for all of it.
#include <morphomap/types.hpp>

namespace morphomap::detail {

inline bool inside(const Vec2& p, const Points2Ref& polygon) {
  bool in = false;
  const Index n = polygon.rows();
  for (Index i = 0, j = n - 1; i < n; j = i++) {
    const double yi = polygon(i, 1), yj = polygon(j, 1);
    if ((yi > p.y()) != (yj > p.y())) {
      const double x = polygon(j, 0) + (p.y() - yj) * (polygon(i, 0) - polygon(j, 0)) / (yi - yj);
      if (p.x() < x) in = !in;
    }
  }
  return in;
}

}  // namespace morphomap::detail
