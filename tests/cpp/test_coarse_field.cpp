// A field carried from coarse copies of two surfaces against the closed form: the radial map
// between concentric spheres, given on a coarse icosphere whose vertices lie on the fine one,
// carried onto the fine sphere's vertices is the radial map there, complete and fold-free.
#include "check.hpp"
#include "mapping/coarse_field.hpp"
#include "surfaces.hpp"

#include <morphomap/quality.hpp>
#include <morphomap/surface_queries.hpp>

#include <algorithm>
#include <cmath>
#include <limits>

using morphomap::DisplacementField3;
using morphomap::Index;
using morphomap::Method;
using morphomap::SurfaceIndex;
using morphomap_test::icosphere;
using morphomap_test::scaled;

namespace {

constexpr double kScale = 1.5;

// The radial map from the coarse sphere onto the coarse copy of the larger one: its vertices'
// ends are the larger sphere's vertices.
DisplacementField3 coarse_radial(const morphomap_test::Surface& c1) {
  DisplacementField3 field;
  field.starts = c1.vertices;
  field.ends = kScale * c1.vertices;
  field.faces = c1.faces;
  field.methods.assign(static_cast<std::size_t>(c1.vertices.rows()), Method::diffusion);
  return field;
}

// Largest distance of the field's ends from the radial image of its starts.
double radial_error(const DisplacementField3& field) {
  double worst = 0.0;
  for (Index i = 0; i < field.size(); ++i) {
    const Eigen::RowVector3d p = field.starts.row(i);
    worst = std::max(worst, (field.ends.row(i) - kScale * p / p.norm()).norm());
  }
  return worst;
}

void test_radial_map_carried_onto_the_fine_sphere() {
  // Subdivision keeps the coarse icosphere's vertices, so the coarse copies lie on the fine ones.
  const auto s1 = icosphere(5), s2 = scaled(icosphere(5), kScale, kScale, kScale);
  const auto c1 = icosphere(2), c2 = scaled(icosphere(2), kScale, kScale, kScale);
  const SurfaceIndex index1(s1.vertices, s1.faces), index2(s2.vertices, s2.faces);
  DisplacementField3 coarse = coarse_radial(c1);
  const DisplacementField3 field = morphomap::detail::carried_from_coarse(
      coarse, c2.vertices, c2.faces, s1.vertices, s1.faces, index1, s2.vertices, s2.faces, index2);
  CHECK(field.size() == s1.vertices.rows());
  CHECK(field.faces == s1.faces);
  for (Index i = 0; i < field.size(); ++i) CHECK(field.valid(i) && field.methods[i] == Method::diffusion);
  // A fine vertex lies up to the coarse facets' sagitta (0.3^2 / 8 = 0.011 at edge 0.3) off
  // them and is located along their normal, up to 0.2 rad from the radial direction: 1.5 x
  // 0.011 x 0.2 = 3.4e-3 at most. A wrong interpolation would be off by a fraction of the coarse
  // edge (0.3).
  CHECK(radial_error(field) < 4e-3);
  CHECK(morphomap::count_folds(field.starts, field.ends, field.faces, s1.vertices, s1.faces, index1, s2.vertices,
                               s2.faces, index2) == 0);
  // A coarse vertex without an end: the fine vertices around it take their neighbours' ends.
  coarse.ends.row(0).setConstant(std::numeric_limits<double>::quiet_NaN());
  const DisplacementField3 holed = morphomap::detail::carried_from_coarse(
      coarse, c2.vertices, c2.faces, s1.vertices, s1.faces, index1, s2.vertices, s2.faces, index2);
  for (Index i = 0; i < holed.size(); ++i) CHECK(holed.valid(i));
  // Within a tenth of the hole's radius (a coarse edge, 0.45 on S2) of the radial map.
  CHECK(radial_error(holed) < 0.045);
}

void test_which_surfaces_are_coarsened_and_how_far() {
  const auto fine = icosphere(5), coarse = icosphere(4);  // 10,242 and 2,562 vertices
  CHECK(morphomap::detail::worth_coarsening(fine.vertices));
  CHECK(!morphomap::detail::worth_coarsening(coarse.vertices));
  // An even mesh of the unit sphere's area 4 pi with 5,000 vertices: edge sqrt(8 pi / (sqrt(3) 5000)).
  const double edge = std::sqrt(8.0 * std::acos(-1.0) / (std::sqrt(3.0) * 5000.0));
  CHECK_NEAR(morphomap::detail::coarse_edge(fine.vertices, fine.faces), edge, 0.002 * edge);
}

}  // namespace

int main() {
  test_radial_map_carried_onto_the_fine_sphere();
  test_which_surfaces_are_coarsened_and_how_far();
  return morphomap_test::failures() == 0 ? 0 : 1;
}
