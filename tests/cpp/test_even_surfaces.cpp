// map_surfaces with MapMethod::optimal: concentric spheres keep the radial map; a sphere onto an
// ellipsoid around it gets a lower QM1 than auto's field, with no fold and every end on S2. The
// descent (through its private header) turns back the triangles of a field folded at the start.
#include "mapping/even_surface.hpp"
#include "quality/folds.hpp"

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

  // The radial field onto the doubled sphere with one end thrown past a neighbour's: its
  // triangles fold; the descent unfolds them, every end staying on S2.
  const morphomap::SurfaceIndex index1(s.vertices, s.faces), index2(twice, s.faces);
  const morphomap::detail::FoldTest test(s.vertices, s.faces, s.vertices, s.faces, index1, twice, s.faces, index2);
  Points3 folded = twice;
  const Index moved = s.faces(0, 0), neighbour = s.faces(0, 1);
  folded.row(moved) = index2
                          .closest_points(Points3(2.0 * (s.vertices.row(moved) +
                                                         2.5 * (s.vertices.row(neighbour) - s.vertices.row(moved)))))
                          .points.row(0);
  Index before = 0;
  for (const char f : test.folded(folded)) before += f;
  CHECK(before > 0);
  const Points3 unfolded = morphomap::detail::even_ends(s.vertices, folded, s.faces, test, twice, s.faces, index2, 4.0);
  Index after = 0;
  for (const char f : test.folded(unfolded)) after += f;
  CHECK(after == 0);
  CHECK(index2.closest_points(unfolded).distances.maxCoeff() < 1e-9);
  TEST_MAIN_END();
}
