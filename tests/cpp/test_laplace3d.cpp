// Diffusion mapping in 3D on shapes with a known answer: between concentric spheres the potential
// is (1/r - 1/R) / (1/r0 - 1/R) and the streamlines are radial.
#include <morphomap/errors.hpp>
#include <morphomap/laplace3d.hpp>
#include <morphomap/quality.hpp>
#include <morphomap/surface_mapping.hpp>

#include <Eigen/Geometry>
#include <Eigen/LU>

#include "check.hpp"
#include "surfaces.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <map>
#include <string>
#include <utility>
#include <vector>

using morphomap::Faces;
using morphomap::Index;
using morphomap::InvalidInput;
using morphomap::Points3;
using morphomap::ShellDiffusionOptions;
using morphomap::solve_diffusion_3d;

using morphomap_test::flipped;
using morphomap_test::icosphere;
using morphomap_test::scaled;
using morphomap_test::Surface;

namespace {

// RMS angle between the directions of starts and ends, times the radius r of the end sphere.
double radial_rms(const Points3& starts, const Points3& ends, double r) {
  double sum = 0.0;
  for (Index i = 0; i < starts.rows(); ++i) {
    const Eigen::Vector3d a = starts.row(i).transpose(), b = ends.row(i).transpose();
    const double angle = std::atan2(a.cross(b).norm(), a.dot(b));
    sum += angle * angle;
  }
  return r * std::sqrt(sum / starts.rows());
}

void concentric_spheres() {
  const Surface inner = scaled(icosphere(3), 1, 1, 1), outer = scaled(icosphere(3), 4, 4, 4);
  ShellDiffusionOptions options;
  options.keep_streamlines = true;
  const auto solution = solve_diffusion_3d(inner.vertices, inner.faces, outer.vertices, outer.faces, options);
  CHECK(solution.ends.rows() == inner.vertices.rows());
  CHECK(solution.ends.allFinite());
  const double rms = radial_rms(inner.vertices, solution.ends, 4.0);
  std::printf("spheres 1 -> 4: %lld tetrahedra, RMS end error %.2e, %.2f s mesh, %.2f s solve, %.2f s trace\n",
              static_cast<long long>(solution.tetrahedra.rows()), rms, solution.seconds.mesh, solution.seconds.solve,
              solution.seconds.trace);
  CHECK(rms < 0.03);  // level-3 spheres; tests/test_diffusion3d.py holds level 4 to 0.01
  // The ends lie on the target, a polyhedron inscribed in the sphere of radius 4.
  for (Index i = 0; i < solution.ends.rows(); ++i) {
    CHECK(solution.ends.row(i).norm() <= 4.0 + 1e-9);
    CHECK(solution.ends.row(i).norm() > 3.97);
  }
  // Potential against the exact one, inside the shell (the mesh boundary is within facet_distance).
  double worst = 0.0;
  for (Index v = 0; v < solution.vertices.rows(); ++v) {
    const double r = solution.vertices.row(v).norm();
    const double exact = (1.0 / r - 0.25) / 0.75;
    worst = std::max(worst, std::abs(solution.potential[v] - std::clamp(exact, 0.0, 1.0)));
  }
  std::printf("spheres 1 -> 4: largest potential error %.2e\n", worst);
  CHECK(worst < 0.02);
  CHECK(solution.streamlines.size() == static_cast<std::size_t>(inner.vertices.rows()));
  CHECK(solution.streamlines[0].rows() >= 3);
  CHECK((solution.streamlines[0].row(0) - inner.vertices.row(0)).norm() == 0.0);
  CHECK((solution.streamlines[0].bottomRows(1) - solution.ends.row(0)).norm() == 0.0);
  // Tetrahedra positively oriented, with volume adding up to the shell (the mesh's approximation).
  double volume = 0.0;
  for (Index t = 0; t < solution.tetrahedra.rows(); ++t) {
    Eigen::Matrix3d e;
    for (int i = 0; i < 3; ++i) {
      e.col(i) =
          (solution.vertices.row(solution.tetrahedra(t, i + 1)) - solution.vertices.row(solution.tetrahedra(t, 0)))
              .transpose();
    }
    CHECK(e.determinant() > 0.0);
    volume += e.determinant() / 6.0;
  }
  const double pi = std::acos(-1.0);
  CHECK_NEAR(volume, 4.0 / 3.0 * pi * (64.0 - 1.0), 0.03 * 4.0 / 3.0 * pi * 63.0);
}

// The outer surface as source: streamlines run inwards; face orientation does not matter.
void inwards_and_flipped() {
  const Surface inner = flipped(scaled(icosphere(3), 1, 1, 1)), outer = scaled(icosphere(2), 3, 3, 3);
  const auto solution = solve_diffusion_3d(outer.vertices, outer.faces, inner.vertices, inner.faces);
  CHECK(solution.ends.allFinite());
  const double rms = radial_rms(outer.vertices, solution.ends, 1.0);
  std::printf("spheres 3 -> 1: RMS end error %.2e\n", rms);
  CHECK(rms < 0.01);
}

// The progress callback hears each stage once, in order.
void stages_reported() {
  const Surface inner = icosphere(2), outer = scaled(icosphere(2), 3, 3, 3);
  std::vector<std::string> stages;
  ShellDiffusionOptions options;
  options.on_stage = [&](const char* stage) { stages.emplace_back(stage); };
  solve_diffusion_3d(inner.vertices, inner.faces, outer.vertices, outer.faces, options);
  CHECK((stages == std::vector<std::string>{"mesh", "solve", "trace"}));
}

// Sphere onto an ellipsoid: every streamline arrives.
void sphere_to_ellipsoid() {
  const Surface sphere = icosphere(3), ellipsoid = scaled(icosphere(3), 2.0, 1.5, 1.2);
  const auto solution = solve_diffusion_3d(sphere.vertices, sphere.faces, ellipsoid.vertices, ellipsoid.faces);
  CHECK(solution.ends.allFinite());
  for (Index i = 0; i < solution.ends.rows(); ++i) {
    const Eigen::RowVector3d q = solution.ends.row(i);
    CHECK_NEAR(q.cwiseQuotient(Eigen::RowVector3d(2.0, 1.5, 1.2)).norm(), 1.0, 0.01);
  }
}

// Crossing surfaces: the unit sphere and an ellipsoid through it. Each start outside the
// ellipsoid bounds the piece sphere \ ellipsoid, so its end lies on the ellipsoid inside the
// sphere, and the other way round.
void crossing_surfaces() {
  const Surface sphere = icosphere(3);
  Surface ellipsoid = scaled(icosphere(3), 1.3, 1.0, 1.0);
  const Eigen::RowVector3d centre(0.6, 0.05, 0.03), axes(1.3, 1.0, 1.0);
  ellipsoid.vertices.rowwise() += centre;
  const auto solution = solve_diffusion_3d(sphere.vertices, sphere.faces, ellipsoid.vertices, ellipsoid.faces);
  CHECK(solution.ends.allFinite());
  int outside = 0;
  for (Index i = 0; i < solution.ends.rows(); ++i) {
    const Eigen::RowVector3d start = sphere.vertices.row(i), end = solution.ends.row(i);
    CHECK_NEAR((end - centre).cwiseQuotient(axes).norm(), 1.0, 0.01);
    const bool start_outside = (start - centre).cwiseQuotient(axes).norm() > 1.0;
    outside += start_outside;
    CHECK(start_outside ? end.norm() < 1.01 : end.norm() > 0.99);
  }
  CHECK(outside > 100 && outside < solution.ends.rows() - 100);
}

void bad_input() {
  const Surface a = icosphere(1), b = scaled(icosphere(1), 3, 3, 3);
  Surface apart = a;
  apart.vertices.col(0).array() += 5.0;
  CHECK_THROWS(solve_diffusion_3d(a.vertices, a.faces, apart.vertices, apart.faces), InvalidInput);
  Surface self_crossing = b;
  self_crossing.vertices.row(0) *= -1.5;  // a spike through the far side
  CHECK_THROWS(solve_diffusion_3d(a.vertices, a.faces, self_crossing.vertices, self_crossing.faces), InvalidInput);
  Surface open = b;
  open.faces.conservativeResize(open.faces.rows() - 1, 3);
  CHECK_THROWS(solve_diffusion_3d(a.vertices, a.faces, open.vertices, open.faces), InvalidInput);
  Surface inconsistent = b;
  inconsistent.faces.row(0) = inconsistent.faces.row(0).reverse().eval();
  CHECK_THROWS(solve_diffusion_3d(a.vertices, a.faces, inconsistent.vertices, inconsistent.faces), InvalidInput);
  Surface out_of_range = a;
  out_of_range.faces(0, 0) = out_of_range.vertices.rows();
  CHECK_THROWS(solve_diffusion_3d(out_of_range.vertices, out_of_range.faces, b.vertices, b.faces), InvalidInput);
  Surface not_finite = a;
  not_finite.vertices(0, 0) = std::nan("");
  CHECK_THROWS(solve_diffusion_3d(not_finite.vertices, not_finite.faces, b.vertices, b.faces), InvalidInput);
  ShellDiffusionOptions negative;
  negative.mesh_size = -1.0;
  CHECK_THROWS(solve_diffusion_3d(a.vertices, a.faces, b.vertices, b.faces, negative), InvalidInput);
}

// Both surfaces are checked at once, but when both are bad the error is s1's, as it was when they
// were checked one after the other: s1 is the larger (slower to check) of the two.
void both_bad_reports_s1() {
  const auto reported = [](const Surface& s1, const Surface& s2) {
    try {
      solve_diffusion_3d(s1.vertices, s1.faces, s2.vertices, s2.faces);
    } catch (const InvalidInput& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  Surface open1 = scaled(icosphere(4), 3, 3, 3), open2 = icosphere(1);
  open1.faces.conservativeResize(open1.faces.rows() - 1, 3);
  open2.faces.conservativeResize(open2.faces.rows() - 1, 3);
  Surface crossing1 = scaled(icosphere(4), 3, 3, 3), crossing2 = icosphere(1);
  crossing1.vertices.row(0) *= -1.5;  // a spike through the far side
  crossing2.vertices.row(0) *= -1.5;
  for (int run = 0; run < 10; ++run) {
    const std::string unclosed = reported(open1, open2), meeting = reported(crossing1, crossing2);
    CHECK(unclosed.rfind("s1", 0) == 0 && unclosed.find("not closed") != std::string::npos);
    CHECK(meeting.rfind("s1: intersects itself", 0) == 0);
  }
}

// S1 a sphere with a pit, S2 1.15 times the sphere with a bud over it: normal mapping folds at the
// pit only, so "auto" keeps the normal vectors elsewhere and diffuses near the pit.
void automatic_diffuses_near_a_bud_only() {
  using morphomap::MapMethod;
  using morphomap::Method;
  const Surface sphere = icosphere(3);
  Surface s1 = sphere, s2 = sphere;
  for (Index i = 0; i < sphere.vertices.rows(); ++i) {
    const double angle = std::acos(std::clamp(sphere.vertices(i, 2), -1.0, 1.0));
    s1.vertices.row(i) *= 1.0 - 0.25 * std::exp(-0.5 * std::pow(angle / 0.2, 2));
    s2.vertices.row(i) *= 1.15 + 0.6 * std::exp(-0.5 * std::pow(angle / 0.4, 2));
  }
  morphomap::SurfaceMappingOptions options;
  options.method = MapMethod::normal;
  const auto normal = morphomap::map_surfaces(s1.vertices, s1.faces, s2.vertices, s2.faces, options);
  CHECK(morphomap::count_folds(normal.starts, normal.ends, normal.faces, s1.vertices, s1.faces, s2.vertices, s2.faces) >
        0);
  options.method = MapMethod::automatic;
  const auto field = morphomap::map_surfaces(s1.vertices, s1.faces, s2.vertices, s2.faces, options);
  CHECK(field.starts == s1.vertices);
  CHECK(field.faces == s1.faces);
  CHECK(morphomap::count_folds(field.starts, field.ends, field.faces, s1.vertices, s1.faces, s2.vertices, s2.faces) ==
        0);
  Index redone = 0;
  for (Index i = 0; i < field.size(); ++i) {
    CHECK(field.valid(i));
    if (field.methods[static_cast<std::size_t>(i)] == Method::normal) {
      CHECK(field.ends.row(i) == normal.ends.row(i));
    } else {
      CHECK(field.methods[static_cast<std::size_t>(i)] == Method::diffusion);
      CHECK(s1.vertices(i, 2) > 0.5);  // near the pit, at the top
      ++redone;
    }
  }
  CHECK(redone > 0 && redone < field.size() / 4);
}

}  // namespace

int main() {
  bad_input();
  both_bad_reports_s1();
  concentric_spheres();
  inwards_and_flipped();
  stages_reported();
  sphere_to_ellipsoid();
  crossing_surfaces();
  automatic_diffuses_near_a_bud_only();
  TEST_MAIN_END();
}
