// The harmonic extension reproduces affine boundary maps at every interior node.
#include <morphomap/errors.hpp>
#include <morphomap/extend.hpp>

#include "check.hpp"

#include <Eigen/LU>

#include <cmath>

using morphomap::DisplacementField2;
using morphomap::DisplacementField3;
using morphomap::extend_field;
using morphomap::ExtendOptions;
using morphomap::ExtensionMethod;
using morphomap::Faces;
using morphomap::Index;
using morphomap::InvalidInput;
using morphomap::Points2;
using morphomap::Points3;
using morphomap::Tetrahedra;

namespace {

void test_2d() {
  const Index n = 60;
  Points2 c1(n, 2);
  for (Index i = 0; i < n; ++i) {
    const double t = 2 * std::acos(-1.0) * i / n;
    c1.row(i) << 2 * std::cos(t), std::sin(t);
  }
  Eigen::Matrix2d a;
  a << 1.2, 0.3, -0.1, 0.9;
  const Eigen::RowVector2d b(0.3, -0.2);
  const Points2 ends = (c1 * a.transpose()).rowwise() + b;
  const DisplacementField2 field{c1, ends, {}};
  ExtendOptions options;
  options.mesh_size = 0.2;
  for (const auto method : {ExtensionMethod::harmonic, ExtensionMethod::elastic}) {
    options.method = method;
    const auto out = extend_field(field, c1, Points2(0, 2), Faces(0, 3), options);
    CHECK(out.points.rows() > n && out.inverted == 0);
    const Points2 expected = ((out.points * a.transpose()).rowwise() + b) - out.points;
    CHECK((out.displacement - expected).cwiseAbs().maxCoeff() < 1e-10);
    CHECK(std::abs(out.min_jacobian - a.determinant()) < 1e-9);
  }
  Faces bad(1, 3);
  bad << 0, 1, 1000;
  CHECK_THROWS(extend_field(field, c1, c1, bad), InvalidInput);
  options.poisson_ratio = 0.5;
  CHECK_THROWS(extend_field(field, c1, Points2(0, 2), Faces(0, 3), options), InvalidInput);
}

void test_3d() {
  // The unit cube: its 8 corners and its centre; 12 boundary triangles, each coned to the centre.
  Points3 points(9, 3);
  for (Index v = 0; v < 8; ++v) points.row(v) << (v & 1), (v >> 1) & 1, (v >> 2) & 1;
  points.row(8) << 0.5, 0.5, 0.5;
  Faces faces(12, 3);
  faces << 0, 2, 1, 1, 2, 3, 4, 5, 6, 5, 7, 6, 0, 1, 4, 1, 5, 4, 2, 6, 3, 3, 6, 7, 0, 4, 2, 2, 4, 6, 1, 3, 5, 3, 7, 5;
  Tetrahedra cells(12, 4);
  for (Index f = 0; f < 12; ++f) cells.row(f) << faces(f, 0), faces(f, 1), faces(f, 2), 8;
  Eigen::Matrix3d a;
  a << 1.1, 0.2, 0, -0.1, 0.9, 0.1, 0.3, 0, 1.2;
  const Points3 corners = points.topRows(8);
  const DisplacementField3 field{corners, corners * a.transpose(), faces, {}};
  ExtendOptions options;
  for (const auto method : {ExtensionMethod::harmonic, ExtensionMethod::elastic}) {
    options.method = method;
    const auto out = extend_field(field, points, cells, options);
    const Points3 expected = points * a.transpose() - points;
    CHECK((out.displacement - expected).cwiseAbs().maxCoeff() < 1e-10);
    CHECK(out.inverted == 0 && out.boundary_distance < 1e-12);
  }
  // No mesh given: Mesh_3 fills the cube, its surface nodes on the cube's faces.
  options.mesh_size = 0.3;
  const auto filled = extend_field(field, Points3(0, 3), Tetrahedra(0, 4), options);
  CHECK(filled.points.rows() > 8);
  const Points3 expected = filled.points * a.transpose() - filled.points;
  CHECK((filled.displacement - expected).cwiseAbs().maxCoeff() < 1e-10);
  CHECK(filled.inverted == 0 && filled.boundary_distance < 1e-12);
}

}  // namespace

int main() {
  test_2d();
  test_3d();
  TEST_MAIN_END();
}
