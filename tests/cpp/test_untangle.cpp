// Untangling against the closed-form optimum: the free centre of a square (a cube), moved outside
// it, goes back to the centre, where the smallest area (volume) ratio of its cells is largest (1);
// the fixed corners do not move, and a mesh without free corners is left as it is.
#include "check.hpp"
#include "diffusion/untangle.hpp"

#include <vector>

using morphomap::Faces;
using morphomap::Index;
using morphomap::Points2;
using morphomap::Points3;
using morphomap::Tetrahedra;
using morphomap::detail::untangle;

namespace {

void test_square() {
  Points2 rest(5, 2);
  rest << 0, 0, 1, 0, 1, 1, 0, 1, 0.5, 0.5;
  Faces cells(4, 3);
  cells << 0, 1, 4, 1, 2, 4, 2, 3, 4, 3, 0, 4;
  const std::vector<char> fixed{1, 1, 1, 1, 0};
  Points2 moved = rest;
  moved.row(4) << 1.7, 0.2;  // outside: two triangles turned over
  CHECK(untangle(rest, moved, cells, fixed, 10) == 1);
  CHECK_NEAR(moved(4, 0), 0.5, 1e-9);
  CHECK_NEAR(moved(4, 1), 0.5, 1e-9);
  CHECK((moved.topRows(4) - rest.topRows(4)).norm() == 0.0);
  // Without a free corner nothing can move.
  Points2 flipped = rest;
  flipped.row(4) << 1.7, 0.2;
  const std::vector<char> all_fixed(5, 1);
  CHECK(untangle(rest, flipped, cells, all_fixed, 10) == 0);
  CHECK(flipped(4, 0) == 1.7 && flipped(4, 1) == 0.2);
}

void test_cube() {
  Points3 rest(9, 3);
  for (Index v = 0; v < 8; ++v) rest.row(v) << (v & 1), ((v >> 1) & 1), ((v >> 2) & 1);
  rest.row(8) << 0.5, 0.5, 0.5;
  // Each face of the cube as two triangles, each with the centre a tetrahedron.
  const int faces[6][4] = {{0, 1, 3, 2}, {4, 5, 7, 6}, {0, 1, 5, 4}, {2, 3, 7, 6}, {0, 2, 6, 4}, {1, 3, 7, 5}};
  Tetrahedra cells(12, 4);
  for (int f = 0; f < 6; ++f) {
    cells.row(2 * f) << faces[f][0], faces[f][1], faces[f][2], 8;
    cells.row(2 * f + 1) << faces[f][0], faces[f][2], faces[f][3], 8;
  }
  std::vector<char> fixed(9, 1);
  fixed[8] = 0;
  Points3 moved = rest;
  moved.row(8) << 0.3, 1.4, -0.2;
  CHECK(untangle(rest, moved, cells, fixed, 10) == 1);
  for (int a = 0; a < 3; ++a) CHECK_NEAR(moved(8, a), 0.5, 1e-9);
  CHECK((moved.topRows(8) - rest.topRows(8)).norm() == 0.0);
}

}  // namespace

int main() {
  test_square();
  test_cube();
  return morphomap_test::failures() == 0 ? 0 : 1;
}
