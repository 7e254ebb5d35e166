// Uses the installed library: closest points on a square, and the library's build information.
#include <morphomap/morphomap.hpp>

#include <cmath>
#include <iostream>

int main() {
  morphomap::Points2 square(4, 2);
  square << 0, 0, 1, 0, 1, 1, 0, 1;
  morphomap::Points2 query(1, 2);
  query << 0.5, -1.0;
  const auto hits = morphomap::closest_points(query, square);
  const auto info = morphomap::build_info();
  std::cout << "morphomap " << info.version << ": distance " << hits.distances[0] << "\n";
  return std::abs(hits.distances[0] - 1.0) < 1e-15 ? 0 : 1;
}
