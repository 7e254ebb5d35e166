// Regression tests of the real-segmentations issue: curves that share a stretch or touch, several
// loops or shells in one input, self-intersections, inward surfaces, "auto" on all of them, and
// interrupts. Run under AddressSanitizer and UndefinedBehaviorSanitizer in CI.
#include <morphomap/crossings.hpp>
#include <morphomap/curve_queries.hpp>
#include <morphomap/errors.hpp>
#include <morphomap/interrupt.hpp>
#include <morphomap/mapping.hpp>
#include <morphomap/quality.hpp>
#include <morphomap/surface_mapping.hpp>
#include <morphomap/surface_queries.hpp>

#include "check.hpp"
#include "shapes.hpp"
#include "surfaces.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>

using morphomap::closest_points;
using morphomap::count_crossings;
using morphomap::CurveMappingOptions;
using morphomap::DisplacementField2;
using morphomap::Index;
using morphomap::InvalidInput;
using morphomap::MapMethod;
using morphomap::Method;
using morphomap::Points2;
using morphomap::SurfaceMappingOptions;
using morphomap_test::icosphere;
using morphomap_test::pi;
using morphomap_test::scaled;

namespace {

const MapMethod kCurveMethods[] = {MapMethod::automatic, MapMethod::minimal_distance, MapMethod::normal,
                                   MapMethod::diffusion, MapMethod::uniform};

// n points of a circle of radius 1; on the right half (|angle| < 80 degrees) C2's radius grows to
// 1.5, its left half is C1's own points: a shared stretch, as consecutive masks give.
Points2 bulging(Index n, double right) {
  Points2 p(n, 2);
  for (Index i = 0; i < n; ++i) {
    const double a = 2 * pi * i / n;
    const double r = std::cos(a) > std::cos(80.0 * pi / 180.0) ? right : 1.0;
    p.row(i) << r * std::cos(a), r * std::sin(a);
  }
  return p;
}

double farthest_from(const Points2& points, const Points2& curve) {
  return closest_points(points, curve, true).distances.maxCoeff();
}

bool all_valid(const DisplacementField2& field) {
  for (Index i = 0; i < field.size(); ++i) {
    if (!field.valid(i)) return false;
  }
  return true;
}

void shared_stretch_is_a_split() {
  const Points2 c1 = bulging(360, 1.0), c2 = bulging(360, 1.5);
  for (const MapMethod method : kCurveMethods) {
    for (const bool reverse : {false, true}) {
      CurveMappingOptions options;
      options.method = method;
      options.reverse = reverse;
      const DisplacementField2 field = morphomap::map_curves(c1, c2, options);
      if (!all_valid(field)) {
        // Only a normal may miss (the line through a point of C2 need not meet C1).
        if (method != MapMethod::normal) {
          std::fprintf(stderr, "method %d reverse %d: a vector missed\n", static_cast<int>(method), reverse);
          CHECK(all_valid(field));
        }
        continue;
      }
      CHECK(farthest_from(field.ends, c2) < 1e-12);
      CHECK(farthest_from(field.starts, c1) < 1e-12);
      // The shared points stay put.
      Index stayed = 0;
      for (Index i = 0; i < field.size(); ++i) stayed += (field.starts.row(i) == field.ends.row(i)) ? 1 : 0;
      CHECK(stayed > 150);
      if (method == MapMethod::diffusion || method == MapMethod::automatic || method == MapMethod::uniform) {
        CHECK(count_crossings(field.starts, field.ends) == 0);
      }
      // Reversed, every vector names a reverse_ variant (but for "auto", whose reverse diffusion
      // pieces then ran from C1 to C2).
      if (reverse && method != MapMethod::automatic) {
        bool reverse_names = true;
        for (const Method m : field.methods) reverse_names = reverse_names && static_cast<int>(m) >= 4;
        CHECK(reverse_names);
      }
    }
  }
}

void touching_circles_are_a_split() {
  // A circle inside another, touching it at (1, 0).
  Points2 inner(200, 2), outer(200, 2);
  for (Index i = 0; i < 200; ++i) {
    const double a = 2 * pi * i / 200;
    inner.row(i) << 0.5 + 0.5 * std::cos(a), 0.5 * std::sin(a);
    outer.row(i) << std::cos(a), std::sin(a);
  }
  for (const MapMethod method : {MapMethod::automatic, MapMethod::diffusion}) {
    CurveMappingOptions options;
    options.method = method;
    const DisplacementField2 field = morphomap::map_curves(inner, outer, options);
    CHECK(all_valid(field));
    CHECK(count_crossings(field.starts, field.ends) == 0);
    CHECK(farthest_from(field.ends, outer) < 1e-12);
    // Not all onto the touching point (a piece from the point round to itself did that).
    Index repeated = 0;
    for (Index i = 1; i < field.size(); ++i) repeated += field.ends.row(i) == field.ends.row(i - 1) ? 1 : 0;
    CHECK(repeated == 0);
  }
}

// split_curves gives the pieces the mapping maps one by one: here the bulge, between the two ends
// of the shared stretch; piece_labels puts each point in it or at the split.
void split_curves_gives_the_bulge() {
  const Points2 c1 = bulging(360, 1.0), c2 = bulging(360, 1.5);
  const morphomap::CurveSplit split = morphomap::split_curves(c1, c2);
  CHECK(split.pieces.size() == 1);
  if (split.pieces.size() != 1) return;
  const morphomap::CurvePiece& piece = split.pieces[0];
  CHECK(piece.begin_meeting && piece.end_meeting);
  // Inside the ends: the 159 vertices at |angle| < 80 degrees, radius 1 on C1 and 1.5 on C2.
  CHECK(piece.source.rows() == 161 && piece.target.rows() == 161);
  for (Index i = 1; i + 1 < std::min(piece.source.rows(), piece.target.rows()); ++i) {
    CHECK_NEAR(piece.target.row(i).norm(), 1.5, 1e-12);
    CHECK(std::abs(std::atan2(piece.source(i, 1), piece.source(i, 0))) < 80.0 * pi / 180.0);
  }
  const morphomap::PieceLabels on_c1 = morphomap::piece_labels(split, c1, true);
  const morphomap::PieceLabels on_c2 = morphomap::piece_labels(split, c2, false);
  for (Index i = 0; i < 360; ++i) {
    const bool bulge = std::cos(2 * pi * i / 360) > std::cos(80.0 * pi / 180.0);
    CHECK(on_c1.piece[i] == (bulge ? 0 : -1) && on_c2.piece[i] == (bulge ? 0 : -1));
  }
  CHECK_THROWS(morphomap::split_curves(c1, c2, true, true, std::nan("")), InvalidInput);
}

std::string message_of(const Points2& c1, const Points2& c2, MapMethod method) {
  CurveMappingOptions options;
  options.method = method;
  try {
    morphomap::map_curves(c1, c2, options);
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "";
}

void several_loops_and_self_intersections_are_named() {
  Points2 two(2 * 41, 2);  // two closed contours, each repeating its first point
  for (Index i = 0; i <= 40; ++i) {
    const double a = 2 * pi * (i % 40) / 40;
    two.row(i) << std::cos(a), std::sin(a);
    two.row(41 + i) << 3 + 0.3 * std::cos(a), 0.3 * std::sin(a);
  }
  Points2 eight(200, 2), big(100, 2);
  for (Index i = 0; i < 200; ++i) {
    const double t = 2 * pi * i / 200;
    eight.row(i) << std::sin(t), std::sin(t) * std::cos(t);
  }
  for (Index i = 0; i < 100; ++i) big.row(i) << 5 * std::cos(2 * pi * i / 100), 5 * std::sin(2 * pi * i / 100);
  for (const MapMethod method : kCurveMethods) {
    CHECK(message_of(two, big, method).rfind("c1: the points form 2 loops", 0) == 0);
    CHECK(message_of(eight, big, method).rfind("c1: the curve intersects itself: 1 pair", 0) == 0);
    CHECK(message_of(big, eight, method).rfind("c2: the curve intersects itself", 0) == 0);
  }
}

std::string surface_message(const morphomap_test::Surface& s1, const morphomap_test::Surface& s2, MapMethod method) {
  SurfaceMappingOptions options;
  options.method = method;
  try {
    morphomap::map_surfaces(s1.vertices, s1.faces, s2.vertices, s2.faces, options);
  } catch (const InvalidInput& e) {
    return e.what();
  }
  return "";
}

void debris_inward_and_unused_vertices_are_named() {
  const auto organ = scaled(icosphere(3), 10, 10, 10);
  const auto debris = morphomap_test::moved(icosphere(1), 20, 0, 0);
  const auto both = morphomap_test::joined(organ, debris);
  const auto outer = scaled(icosphere(3), 12, 12, 12);
  morphomap_test::Surface unused = organ;
  unused.vertices.conservativeResize(unused.vertices.rows() + 1, 3);
  unused.vertices.row(unused.vertices.rows() - 1) << 50, 50, 50;
  for (const MapMethod method :
       {MapMethod::automatic, MapMethod::minimal_distance, MapMethod::normal, MapMethod::diffusion}) {
    CHECK(surface_message(both, outer, method).rfind("s1: the surface has 2 separate components (1280, 80 faces)", 0) ==
          0);
    CHECK(
        surface_message(outer, morphomap_test::flipped(organ), method).rfind("s2: the faces are oriented inwards", 0) ==
        0);
    CHECK(surface_message(unused, outer, method).rfind("s1: vertex 642", 0) == 0);
  }
}

void surfaces_that_coincide_over_a_patch_map() {
  // S2 is S1 with its upper half pushed out: the lower half coincides, where the region between
  // them has no volume. Auto answers; diffusion cuts the shared patch out: its vertices stay where
  // they are, the others follow streamlines, and no triangle folds.
  morphomap_test::Surface s1 = scaled(icosphere(3), 1, 1, 1), s2 = s1;
  for (Index i = 0; i < s2.vertices.rows(); ++i) {
    if (s2.vertices(i, 2) > 0.2) s2.vertices.row(i) *= 1.0 + (s2.vertices(i, 2) - 0.2);
  }
  const morphomap::SurfaceIndex on_s2(s2.vertices, s2.faces);
  for (const MapMethod method : {MapMethod::automatic, MapMethod::diffusion}) {
    SurfaceMappingOptions options;
    options.method = method;
    const auto field = morphomap::map_surfaces(s1.vertices, s1.faces, s2.vertices, s2.faces, options);
    bool valid = true;
    for (Index i = 0; i < field.size(); ++i) valid = valid && field.valid(i);
    CHECK(valid);
    CHECK(on_s2.closest_points(field.ends).distances.maxCoeff() < 1e-9);
    if (method != MapMethod::diffusion) continue;
    bool shared_stay = true, others_follow_streamlines = true;
    for (Index i = 0; i < field.size(); ++i) {
      if (s1.vertices(i, 2) <= 0.2) {
        shared_stay = shared_stay && field.methods[i] == Method::minimal_distance &&
                      (field.ends.row(i) - field.starts.row(i)).norm() < 1e-12;
      } else if (s1.vertices(i, 2) > 0.4) {
        others_follow_streamlines = others_follow_streamlines && field.methods[i] == Method::diffusion &&
                                    (field.ends.row(i) - field.starts.row(i)).norm() > 1e-3;
      }
    }
    CHECK(shared_stay);
    CHECK(others_follow_streamlines);
    CHECK(morphomap::quality(field, s1.vertices, s1.faces, s2.vertices, s2.faces).folds == 0);
  }
}

void an_interrupt_stops_a_mapping() {
  const Points2 c1 = bulging(2000, 1.0), c2 = bulging(2000, 1.5);
  CurveMappingOptions options;
  options.method = MapMethod::diffusion;
  morphomap::request_interrupt();
  CHECK_THROWS(morphomap::map_curves(c1, c2, options), morphomap::Interrupted);
  morphomap::clear_interrupt();
  CHECK(all_valid(morphomap::map_curves(c1, c2, options)));
}

}  // namespace

int main() {
  shared_stretch_is_a_split();
  touching_circles_are_a_split();
  split_curves_gives_the_bulge();
  several_loops_and_self_intersections_are_named();
  debris_inward_and_unused_vertices_are_named();
  surfaces_that_coincide_over_a_patch_map();
  an_interrupt_stops_a_mapping();
  TEST_MAIN_END();
}
