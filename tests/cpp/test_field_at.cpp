// The field anywhere on its source boundary: affine maps are reproduced exactly between the
// start points (2D, along a polygon's sides; 3D, inside the start triangles).
#include <morphomap/errors.hpp>
#include <morphomap/field_at.hpp>

#include "check.hpp"
#include "surfaces.hpp"

#include <cmath>

using morphomap::displacement_at;
using morphomap::DisplacementField2;
using morphomap::DisplacementField3;
using morphomap::Index;
using morphomap::InvalidInput;
using morphomap::Points2;
using morphomap::Points3;

namespace {

void test_curves() {
  Points2 c1(4, 2);
  c1 << 0, 0, 2, 0, 2, 1, 0, 1;
  Eigen::Matrix2d a;
  a << 1.1, 0.2, -0.3, 0.8;
  const Eigen::RowVector2d b(0.4, -0.2);
  DisplacementField2 field;
  // The vectors in a scrambled order: placing them by arc length does not care.
  const Index order[4] = {2, 0, 3, 1};
  field.starts.resize(4, 2);
  field.ends.resize(4, 2);
  for (Index k = 0; k < 4; ++k) {
    field.starts.row(k) = c1.row(order[k]);
    field.ends.row(k) = c1.row(order[k]) * a.transpose() + b;
  }
  Points2 points(5, 2);
  points << 1, 0, 2, 0.25, 0.5, 1, 0, 0.5, 2, 1;
  const auto at = displacement_at(field, c1, true, points);
  for (Index q = 0; q < points.rows(); ++q) {
    const Eigen::RowVector2d expected = points.row(q) * a.transpose() + b - points.row(q);
    CHECK((at.displacements.row(q) - expected).norm() < 1e-12);
    CHECK(at.distances(q) < 1e-12);
  }
  CHECK_THROWS(displacement_at(field, c1.topRows(1), true, points), InvalidInput);
  Points2 bad = points;
  bad(0, 0) = std::nan("");
  CHECK_THROWS(displacement_at(field, c1, true, bad), InvalidInput);
}

void test_surfaces() {
  const auto s = morphomap_test::icosphere(2);
  Eigen::Matrix3d a;
  a << 1.1, 0.2, 0, 0, 0.9, 0.1, 0.3, 0, 1.2;
  DisplacementField3 field{s.vertices, s.vertices * a.transpose(), s.faces, {}};
  Points3 centroids(s.faces.rows(), 3);
  for (Index f = 0; f < s.faces.rows(); ++f) {
    centroids.row(f) =
        (s.vertices.row(s.faces(f, 0)) + s.vertices.row(s.faces(f, 1)) + s.vertices.row(s.faces(f, 2))) / 3;
  }
  const auto at = displacement_at(field, centroids);
  const Points3 expected = centroids * a.transpose() - centroids;
  CHECK((at.displacements - expected).cwiseAbs().maxCoeff() < 1e-12);
  CHECK(at.distances.maxCoeff() < 1e-12);
  field.faces.resize(0, 3);
  CHECK_THROWS(displacement_at(field, centroids), InvalidInput);
}

}  // namespace

int main() {
  test_curves();
  test_surfaces();
  TEST_MAIN_END();
}
