// The barrier untangling of a 3D field on S2 (auto's last resort, through its private header): a
// radial field onto the doubled sphere whose cap of ends is mirrored (every triangle there turned
// over, a band of them torn at its rim) comes back with no fold, every end on S2, and the ends it
// was told to hold exactly where they were.
#include "mapping/barrier_untangle.hpp"
#include "quality/folds.hpp"

#include <morphomap/surface_queries.hpp>

#include "check.hpp"
#include "surfaces.hpp"

#include <vector>

using morphomap::Index;
using morphomap::Points3;

namespace {

Index folds(const morphomap::detail::FoldTest& test, const Points3& ends) {
  Index count = 0;
  for (const char f : test.folded(ends)) count += f;
  return count;
}

}  // namespace

int main() {
  const auto s = morphomap_test::icosphere(3);
  const Points3 twice = 2.0 * s.vertices;
  const morphomap::SurfaceIndex index1(s.vertices, s.faces), index2(twice, s.faces);
  const morphomap::detail::FoldTest test(s.vertices, s.faces, s.vertices, s.faces, index1, twice, s.faces, index2);
  // The ends above z = 0.7 mirrored in the plane y = 0 (still on the doubled sphere).
  Points3 mirrored = twice;
  for (Index v = 0; v < s.vertices.rows(); ++v) {
    if (s.vertices(v, 2) > 0.7) mirrored(v, 1) = -mirrored(v, 1);
  }
  const Index before = folds(test, mirrored);
  CHECK(before > 100);
  const double alpha = 4.0;  // area(S2) / area(S1)

  // Every end free.
  const std::vector<char> none(static_cast<std::size_t>(s.vertices.rows()), 0);
  const auto untangled = morphomap::detail::barrier_untangled(s.vertices, mirrored, s.faces, test, none, s.faces, twice,
                                                              index2, alpha, 30);
  CHECK(untangled.has_value());
  const Points3 free = untangled.value_or(mirrored);
  CHECK(folds(test, free) == 0);
  CHECK(index2.closest_points(free).distances.maxCoeff() < 1e-9);

  // The lower half held: it stays bit for bit, and the rest untangles around it.
  std::vector<char> held(static_cast<std::size_t>(s.vertices.rows()), 0);
  for (Index v = 0; v < s.vertices.rows(); ++v) held[static_cast<std::size_t>(v)] = s.vertices(v, 2) < 0.0;
  const auto held_around = morphomap::detail::barrier_untangled(s.vertices, mirrored, s.faces, test, held, s.faces,
                                                                twice, index2, alpha, 30);
  CHECK(held_around.has_value());
  const Points3 around = held_around.value_or(mirrored);
  CHECK(folds(test, around) == 0);
  CHECK(index2.closest_points(around).distances.maxCoeff() < 1e-9);
  for (Index v = 0; v < s.vertices.rows(); ++v) {
    if (held[static_cast<std::size_t>(v)]) CHECK((around.row(v) - mirrored.row(v)).norm() == 0.0);
  }
  TEST_MAIN_END();
}
