// map_surfaces with MapMethod::optimal: concentric spheres keep the radial map; a sphere onto an
// ellipsoid around it gets a lower QM1 than auto's field, with no fold and every end on S2.
#include <morphomap/quality.hpp>
#include <morphomap/surface_mapping.hpp>
#include <morphomap/surface_queries.hpp>

#include "check.hpp"
#include "surfaces.hpp"

using morphomap::Index;
using morphomap::map_surfaces;
using morphomap::MapMethod;
using morphomap::Method;
using morphomap::Points3;
using morphomap::SurfaceMappingOptions;

int main() {
  const auto s = morphomap_test::icosphere(3);
  SurfaceMappingOptions options;
  options.method = MapMethod::optimal;
  const Points3 twice = 2.0 * s.vertices;
  const auto radial = map_surfaces(s.vertices, s.faces, twice, s.faces, options);
  CHECK((radial.ends - twice).cwiseAbs().maxCoeff() < 1e-5);
  CHECK(radial.methods[0] == Method::optimal);

  Points3 ellipsoid = s.vertices;
  ellipsoid.col(0) *= 1.6;
  ellipsoid.col(1) *= 1.2;
  ellipsoid.col(2) *= 1.1;
  const auto even = map_surfaces(s.vertices, s.faces, ellipsoid, s.faces, options);
  const auto automatic = map_surfaces(s.vertices, s.faces, ellipsoid, s.faces);
  const auto q_even = morphomap::quality(even, s.vertices, s.faces, ellipsoid, s.faces);
  const auto q_auto = morphomap::quality(automatic, s.vertices, s.faces, ellipsoid, s.faces);
  CHECK(q_even.folds == 0);
  CHECK(q_even.qm1 < 0.01 * q_auto.qm1);
  const auto on = morphomap::closest_points(even.ends, ellipsoid, s.faces);
  CHECK(on.distances.maxCoeff() < 1e-9);
  TEST_MAIN_END();
}
