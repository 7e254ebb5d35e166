// Isotropic remeshing of closed surfaces: the result is closed, in one piece, as oriented as the
// input, on the input surface and near the asked edge length.
#include <morphomap/errors.hpp>
#include <morphomap/remesh.hpp>
#include <morphomap/surface_queries.hpp>

#include "check.hpp"
#include "surfaces.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

using morphomap::check_closed_surface;
using morphomap::closest_points;
using morphomap::Index;
using morphomap::InvalidInput;
using morphomap::remesh_surface;
using morphomap_test::icosphere;

namespace {

std::vector<double> edge_lengths(const morphomap::TriangleSurface& s) {
  std::vector<double> lengths;
  for (Index f = 0; f < s.faces.rows(); ++f) {
    for (int i = 0; i < 3; ++i) {
      lengths.push_back((s.vertices.row(s.faces(f, i)) - s.vertices.row(s.faces(f, (i + 1) % 3))).norm());
    }
  }
  std::sort(lengths.begin(), lengths.end());
  return lengths;
}

void test_sphere() {
  // A fine ellipsoid remeshed coarser and finer than it is: closed and outward (check_closed_surface
  // throws otherwise), its vertices on the input, its median edge near the target.
  const auto input = morphomap_test::scaled(icosphere(4), 2.0, 1.0, 1.0);  // edges ~0.08 .. 0.16
  for (const double target : {0.05, 0.3}) {
    const auto out = remesh_surface(input.vertices, input.faces, target, 5);
    CHECK(check_closed_surface(out.vertices, out.faces, "out") > 0);
    const auto lengths = edge_lengths(out);
    const double median = lengths[lengths.size() / 2];
    CHECK(median > 0.75 * target && median < 1.3 * target);
    const auto hits = closest_points(out.vertices, input.vertices, input.faces);
    CHECK(hits.distances.maxCoeff() < 1e-9 * target);
  }
  // Orientation is kept.
  const auto inward = morphomap_test::flipped(input);
  const auto out = remesh_surface(inward.vertices, inward.faces, 0.3, 2);
  CHECK(check_closed_surface(out.vertices, out.faces, "out") < 0);
}

void test_validation() {
  const auto s = icosphere(1);
  CHECK_THROWS(remesh_surface(s.vertices, s.faces, 0.0, 1), InvalidInput);
  CHECK_THROWS(remesh_surface(s.vertices, s.faces, std::nan(""), 1), InvalidInput);
  CHECK_THROWS(remesh_surface(s.vertices, s.faces, 0.1, 0), InvalidInput);
  CHECK_THROWS(remesh_surface(s.vertices, s.faces.topRows(10), 0.1, 1), InvalidInput);  // open
  const auto two = morphomap_test::joined(s, morphomap_test::moved(s, 3, 0, 0));
  CHECK_THROWS(remesh_surface(two.vertices, two.faces, 0.1, 1), InvalidInput);
  morphomap::Faces out_of_range = s.faces;
  out_of_range(0, 0) = 1000;
  CHECK_THROWS(remesh_surface(s.vertices, out_of_range, 0.1, 1), InvalidInput);
}

}  // namespace

int main() {
  test_sphere();
  test_validation();
  TEST_MAIN_END();
}
