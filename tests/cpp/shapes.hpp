#pragma once
// Small polygons written out by hand, shared by the C++ unit tests.
#include <morphomap/types.hpp>

#include <cmath>
#include <initializer_list>
#include <utility>

namespace morphomap_test {

const double pi = std::acos(-1.0);

inline morphomap::Points2 pts(std::initializer_list<std::pair<double, double>> list) {
  morphomap::Points2 p(static_cast<morphomap::Index>(list.size()), 2);
  morphomap::Index i = 0;
  for (const auto& [x, y] : list) p.row(i++) << x, y;
  return p;
}

// Axis-parallel rectangle, counter-clockwise from its lower left corner.
inline morphomap::Points2 rect(double x0, double y0, double x1, double y1) {
  return pts({{x0, y0}, {x1, y0}, {x1, y1}, {x0, y1}});
}

}  // namespace morphomap_test
