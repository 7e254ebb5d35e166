// map_curves against closed forms and brute force, as the Python tests check it: normal rays onto
// a circle, minimal distance against every segment, uniform's exact proportions, the split at
// the four crossings of two ellipses, reverse, the automatic workflow, named bad input, and
// prepared curves giving the plain calls' fields and quality bit for bit.
#include <morphomap/crossings.hpp>
#include <morphomap/errors.hpp>
#include <morphomap/mapping.hpp>
#include <morphomap/prepared_curve.hpp>
#include <morphomap/quality.hpp>

#include "check.hpp"
#include "shapes.hpp"

#include <algorithm>
#include <cmath>
#include <complex>
#include <exception>
#include <string>
#include <vector>

using morphomap::CurveMappingOptions;
using morphomap::DisplacementField2;
using morphomap::Index;
using morphomap::InvalidInput;
using morphomap::map_curves;
using morphomap::MapMethod;
using morphomap::Method;
using morphomap::Points2;
using morphomap::PreparedCurve;
using morphomap_test::pi;

namespace {

// n points counter-clockwise from angle `phase` on the ellipse with semi-axes a, b.
Points2 ellipse(Index n, double a, double b, double phase = 0.0) {
  Points2 p(n, 2);
  for (Index i = 0; i < n; ++i) {
    const double t = phase + 2 * pi * static_cast<double>(i) / static_cast<double>(n);
    p.row(i) << a * std::cos(t), b * std::sin(t);
  }
  return p;
}

DisplacementField2 map(const Points2& c1, const Points2& c2, MapMethod method, bool reverse = false) {
  CurveMappingOptions options;
  options.method = method;
  options.reverse = reverse;
  return map_curves(c1, c2, options);
}

bool all_are(const DisplacementField2& field, Method method) {
  return std::all_of(field.methods.begin(), field.methods.end(), [&](Method m) { return m == method; });
}

std::string message_of(const Points2& c1, const Points2& c2) {
  try {
    map(c1, c2, MapMethod::automatic);
  } catch (const InvalidInput& error) {
    return error.what();
  }
  return "";
}

void normal_rays_meet_the_outer_circle() {
  // Radial normals of a regular 100-gon onto a 20000-gon of radius 2: each end lies on the ray
  // through its start, within the polygon's sagitta of radius 2.
  const Points2 c1 = ellipse(100, 1.0, 1.0), c2 = ellipse(20000, 2.0, 2.0);
  const DisplacementField2 field = map(c1, c2, MapMethod::normal);
  CHECK(field.size() == 100 && all_are(field, Method::normal));
  const double sagitta = 2.0 * (1 - std::cos(pi / 20000));
  for (Index i = 0; i < field.size(); ++i) {
    CHECK(field.starts.row(i) == c1.row(i));
    CHECK_NEAR(field.ends.row(i).norm(), 2.0, sagitta + 1e-12);
    CHECK_NEAR(field.ends(i, 0) * c1(i, 1) - field.ends(i, 1) * c1(i, 0), 0.0, 1e-12);  // on the ray
  }
}

void minimal_distance_equals_brute_force() {
  const Points2 c1 = ellipse(100, 0.95, 0.95), c2 = ellipse(3000, 2.177, 1.0);
  const DisplacementField2 field = map(c1, c2, MapMethod::minimal_distance);
  CHECK(all_are(field, Method::minimal_distance));
  for (Index i = 0; i < field.size(); ++i) {
    double best = 1e300;
    for (Index k = 0; k < c2.rows(); ++k) {
      const Eigen::Vector2d a = c2.row(k), e = c2.row((k + 1) % c2.rows()) - c2.row(k);
      const Eigen::Vector2d p = field.starts.row(i);
      const double t = std::clamp((p - a).dot(e) / e.squaredNorm(), 0.0, 1.0);
      best = std::min(best, (a + t * e - p).norm());
    }
    CHECK_NEAR((field.ends.row(i) - field.starts.row(i)).norm(), best, 1e-12);
  }
}

void uniform_keeps_proportions() {
  // Open lines: the arc-length fraction of each start point, exactly.
  Points2 c1(11, 2), c2(7, 2);
  for (Index i = 0; i < 11; ++i) c1.row(i) << i / 10.0, 0.0;
  for (Index i = 0; i < 7; ++i) c2.row(i) << 3.0 * i / 6.0, 1.0;
  CurveMappingOptions options;
  options.method = MapMethod::uniform;
  options.closed = false;
  const DisplacementField2 open = map_curves(c1, c2, options);
  for (Index i = 0; i < 11; ++i) {
    CHECK_NEAR(open.ends(i, 0), 3.0 * i / 10.0, 1e-14);
    CHECK_NEAR(open.ends(i, 1), 1.0, 1e-14);
  }
  // Closed: the same circle of radius 2 starting five points later; the best cyclic shift is the
  // radial map.
  const Points2 circle1 = ellipse(64, 1.0, 1.0), circle2 = ellipse(64, 2.0, 2.0, 2 * pi * 5 / 64);
  const DisplacementField2 closed = map(circle1, circle2, MapMethod::uniform);
  CHECK((closed.ends - 2.0 * circle1).cwiseAbs().maxCoeff() < 1e-12);
}

void split_ellipses_do_not_cross() {
  // Ellipses 2 x 1 and 1 x 2 cross at (+-2/sqrt 5, +-2/sqrt 5): four fixed points are inserted.
  const Points2 c1 = ellipse(400, 2.0, 1.0), c2 = ellipse(400, 1.0, 2.0);
  for (MapMethod method : {MapMethod::minimal_distance, MapMethod::uniform}) {
    const DisplacementField2 field = map(c1, c2, method);
    CHECK(field.size() == 404);
    int fixed = 0;
    for (Index i = 0; i < field.size(); ++i) {
      CHECK(field.valid(i));
      if (field.starts.row(i) == field.ends.row(i)) {
        ++fixed;
        CHECK_NEAR(std::abs(field.starts(i, 0)), 2 / std::sqrt(5.0), 1e-4);  // polyline vs ellipse
        CHECK_NEAR(std::abs(field.starts(i, 1)), 2 / std::sqrt(5.0), 1e-4);
      }
    }
    CHECK(fixed == 4);
    CHECK(morphomap::count_crossings(field.starts, field.ends) == 0);
  }
}

void reverse_starts_on_c1_in_c2_order() {
  const Points2 c1 = ellipse(50, 1.0, 1.0), c2 = ellipse(80, 2.0, 1.5);
  const DisplacementField2 field = map(c1, c2, MapMethod::minimal_distance, true);
  CHECK(field.size() == 80 && all_are(field, Method::reverse_minimal_distance));
  CHECK(field.ends == c2);
  for (Index i = 0; i < field.size(); ++i) CHECK_NEAR(field.starts.row(i).norm(), 1.0, 1 - std::cos(pi / 50));
}

void automatic_maps_concentric_circles_radially() {
  // Algorithm 1 ("paper"): normal mapping has neither crossings nor misses here, so it is kept.
  // The default picks the lowest QM among its candidates, which on concentric circles are all
  // the radial map up to C2's polygon: each end within one edge's angle of its start's direction.
  const Points2 c1 = ellipse(200, 1.0, 1.0), c2 = ellipse(2000, 1.5, 1.5);
  CHECK(all_are(map(c1, c2, MapMethod::paper), Method::normal));
  const DisplacementField2 field = map(c1, c2, MapMethod::automatic);
  CHECK(morphomap::count_crossings(field.starts, field.ends) == 0);
  for (Index i = 0; i < field.size(); ++i) {
    CHECK_NEAR(field.ends.row(i).norm(), 1.5, 1.5 * (1 - std::cos(pi / 2000)) + 1e-12);
    const double turn = std::arg(std::complex<double>(field.ends(i, 0), field.ends(i, 1)) /
                                 std::complex<double>(field.starts(i, 0), field.starts(i, 1)));
    CHECK(std::abs(turn) < 2 * pi / 2000);
  }
}

void bad_curves_are_named() {
  const Points2 eight = morphomap_test::pts({{0, 0}, {1, 1}, {1, 0}, {0, 1}});
  const Points2 big = ellipse(40, 3.0, 3.0);
  CHECK(message_of(eight, big).rfind("c1: the curve intersects itself", 0) == 0);
  CHECK(message_of(big, eight).rfind("c2: the curve intersects itself", 0) == 0);
  const Points2 flat = morphomap_test::pts({{0, 0}, {1, 0}, {2, 0}});
  CHECK(message_of(flat, big).rfind("c1:", 0) == 0);
  Points2 nan = big;
  nan(3, 1) = std::nan("");
  CHECK(message_of(big, nan).rfind("c2:", 0) == 0);
}

// Equal arrays, NaN where the other is NaN.
bool identical(const Points2& a, const Points2& b) {
  return a.rows() == b.rows() && ((a.array() == b.array()) || (a.array().isNaN() && b.array().isNaN())).all();
}

bool same_number(double a, double b) { return a == b || (std::isnan(a) && std::isnan(b)); }

// map_curves and quality on prepared curves (checked and indexed once) against the plain calls:
// the same fields and quality, bit for bit, over the methods and the options that change which
// curves the mapping runs on (resampled, moved) and which indices it may reuse.
// The registry: every MapMethod's name reads back as it; other names are refused with the list.
void method_names_round_trip() {
  for (const MapMethod method : morphomap::kMapMethods) {
    CHECK(morphomap::map_method_named(morphomap::map_method_name(method)) == method);
  }
  CHECK(std::string(morphomap::map_method_name(MapMethod::automatic)) == "auto");
  try {
    (void)morphomap::map_method_named("automatic");
    CHECK(false);
  } catch (const InvalidInput& e) {
    CHECK(std::string(e.what()) ==
          "method: expected one of 'auto', 'minimal_distance', 'normal', 'diffusion', 'uniform', 'optimal' or "
          "'paper', got 'automatic'");
  }
  for (int code = 0; code < morphomap::kMethodCount; ++code) {
    const Method method = static_cast<Method>(code);
    const std::string name = morphomap::method_name(method);
    CHECK(name != "unknown");
    CHECK(morphomap::method_name(morphomap::reversed(method)) ==
          (name.rfind("reverse_", 0) == 0 ? name.substr(8) : "reverse_" + name));
  }
}

void prepared_curves_give_the_plain_results() {
  Points2 wavy = ellipse(300, 1.4, 0.9);  // crosses the circle four times (split)
  for (Index i = 0; i < wavy.rows(); ++i) wavy.row(i) *= 1.0 + 0.05 * std::sin(7 * 2 * pi * i / 300.0);
  Points2 closing = ellipse(200, 1.0, 1.0, 0.1);  // a closing repeat of the first point
  closing.conservativeResize(201, 2);
  closing.row(200) = closing.row(0);
  const Points2 outer = ellipse(250, 1.6, 1.3, 0.3);  // nested around both: no crossing
  struct Pair {
    const Points2 *c1, *c2;
    bool closed;
  };
  const Points2 open1 = ellipse(80, 1.0, 1.0).topRows(40), open2 = ellipse(90, 1.3, 1.2).topRows(45);
  const std::vector<Pair> pairs = {{&closing, &wavy, true}, {&closing, &outer, true}, {&open1, &open2, false}};
  for (const Pair& pair : pairs) {
    const PreparedCurve p1(*pair.c1, pair.closed, "frame 1"), p2(*pair.c2, pair.closed, "frame 2");
    CHECK(p1.points() == *pair.c1 && p1.closed() == pair.closed);
    for (const MapMethod method : {MapMethod::automatic, MapMethod::normal, MapMethod::minimal_distance,
                                   MapMethod::uniform, MapMethod::diffusion, MapMethod::optimal}) {
      for (int variant = 0; variant < 4; ++variant) {
        CurveMappingOptions options;
        options.method = method;
        options.closed = pair.closed;
        options.reverse = variant == 1;
        options.n = variant == 2 ? 120 : 0;
        options.transform = variant == 3;
        DisplacementField2 plain;
        try {
          plain = map_curves(*pair.c1, *pair.c2, options);
        } catch (const std::exception& refused) {  // then refused alike
          try {
            map_curves(p1, p2, options);
            CHECK(false);
          } catch (const std::exception& e) {
            CHECK(std::string(e.what()) == refused.what());
          }
          continue;
        }
        const DisplacementField2 prepared = map_curves(p1, p2, options);
        CHECK(identical(prepared.starts, plain.starts) && identical(prepared.ends, plain.ends));
        CHECK(prepared.methods == plain.methods);
        const morphomap::CurveQuality a = morphomap::quality(plain, *pair.c1, *pair.c2, pair.closed);
        const morphomap::CurveQuality b = morphomap::quality(prepared, p1, p2, pair.closed);
        CHECK(same_number(a.qm1, b.qm1) && same_number(a.qm2, b.qm2) && same_number(a.qm, b.qm));
        CHECK(a.crossings == b.crossings);
      }
    }
  }
  // Prepared open, asked closed (or the other way round): named; a bad curve: named as prepared.
  const PreparedCurve circle(ellipse(50, 1.0, 1.0), true, "frame 1"), arc(open1, false, "frame 2");
  CurveMappingOptions closed;
  try {
    map_curves(circle, arc, closed);
    CHECK(false);
  } catch (const InvalidInput& e) {
    CHECK(std::string(e.what()).rfind("c2: was prepared as an open curve", 0) == 0);
  }
  const DisplacementField2 field = map_curves(circle, circle, closed);
  CHECK_THROWS(morphomap::quality(field, arc, circle, true), InvalidInput);
  try {
    morphomap::quality(field, circle, circle, false);
    CHECK(false);
  } catch (const InvalidInput& e) {
    CHECK(std::string(e.what()).rfind("c1: was prepared as a closed curve", 0) == 0);
  }
  try {
    const PreparedCurve bad(morphomap_test::pts({{0, 0}, {1, 1}, {1, 0}, {0, 1}}), true, "frames[3]");
    CHECK(false);
  } catch (const InvalidInput& e) {
    CHECK(std::string(e.what()).rfind("frames[3]: the curve intersects itself", 0) == 0);
  }
}

}  // namespace

int main() {
  normal_rays_meet_the_outer_circle();
  minimal_distance_equals_brute_force();
  uniform_keeps_proportions();
  split_ellipses_do_not_cross();
  reverse_starts_on_c1_in_c2_order();
  automatic_maps_concentric_circles_radially();
  bad_curves_are_named();
  prepared_curves_give_the_plain_results();
  method_names_round_trip();
  TEST_MAIN_END();
}
