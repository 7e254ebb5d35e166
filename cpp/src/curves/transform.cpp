// The paper's Appendix A: scale C1 to the area of C2, then greedy rigid steps that increase the
// overlap area (the paper's pseudo-code tests the sign the wrong way round and assigns an
// undefined A_temp; this follows its stated intent).
#include <morphomap/curve_geometry.hpp>
#include <morphomap/transform.hpp>

#include "common/validation.hpp"

#include <tbb/parallel_for.h>

#include <array>
#include <cmath>
#include <string>
#include <utility>

namespace morphomap {
namespace {

const double pi = std::acos(-1.0);

// Starting steps of the greedy search: translations by a tenth of the size of C2 and rotations by
// 10 degrees; a rotation by 10 degrees moves a point at 0.6 size from the centroid by about the
// same 0.1 size. Both are halved whenever no move helps.
constexpr double initial_step = 0.1;
constexpr double initial_turn_degrees = 10.0;
// Bound on the rounds (one round tries every move once), so that no input can hang the search.
// A round either moves (strictly increasing the area) or halves the steps; a few hundred are
// usual.
constexpr int max_rounds = 2000;

// A closed curve without repeats, checked: finite, at least 3 distinct points, non-zero area
// and simple (the overlap area is defined for simple curves only).
Points2 checked_closed(const Points2Ref& points, const char* name) {
  int turn = 0;
  Points2 q = detail::oriented_closed_curve(points, name, turn);
  if (is_self_intersecting(q, true)) {
    detail::invalid(name, "the closed curve intersects itself; the overlap area needs a simple curve");
  }
  return q;
}

// Area and area centroid of a polygon, relative to its first point for accuracy.
std::pair<double, Vec2> area_centroid(const Points2& p) {
  const Index n = p.rows();
  const Vec2 o = p.row(0).transpose();
  double twice = 0.0;
  Vec2 moment = Vec2::Zero();
  for (Index i = 1; i + 1 < n; ++i) {
    const Vec2 u = p.row(i).transpose() - o, v = p.row(i + 1).transpose() - o;
    const double c = u.x() * v.y() - v.x() * u.y();
    twice += c;
    moment += c * (u + v);
  }
  return {std::abs(0.5 * twice), o + moment / (3.0 * twice)};
}

Similarity2 align_open(const Points2Ref& c1, const Points2Ref& c2) {
  const Index n1 = detail::require_curve(c1, false, "c1");
  const Index n2 = detail::require_curve(c2, false, "c2");
  const Vec2 p0 = c1.row(0).transpose(), p1 = c1.row(n1 - 1).transpose();
  const Vec2 q0 = c2.row(0).transpose(), q1 = c2.row(n2 - 1).transpose();
  if (p0 == p1) detail::invalid("c1", "the first and last points of the open curve coincide");
  if (q0 == q1) detail::invalid("c2", "the first and last points of the open curve coincide");
  const Vec2 d1 = p1 - p0, d2 = q1 - q0;
  Similarity2 t;
  // About the midpoint of C1's chord, which goes onto the midpoint of C2's chord.
  t.centre = 0.5 * (p0 + p1);
  t.translation = 0.5 * (q0 + q1) - t.centre;
  t.scale = d2.norm() / d1.norm();
  t.angle = std::atan2(d1.x() * d2.y() - d1.y() * d2.x(), d1.dot(d2));
  return t;
}

Similarity2 align_closed(const Points2Ref& c1, const Points2Ref& c2, double tolerance) {
  const Points2 p1 = checked_closed(c1, "c1");
  const Points2 p2 = checked_closed(c2, "c2");
  const auto [area1, centroid1] = area_centroid(p1);
  const auto [area2, centroid2] = area_centroid(p2);
  const double size = std::sqrt(area2);

  // Scaled about the centroid of C1 to the area of C2; rotations then turn about the moved
  // centroid, centre + translation, so that a rotation changes only the angle.
  Similarity2 t;
  t.centre = centroid1;
  t.scale = std::sqrt(area2 / area1);
  const auto overlap = [&](const Similarity2& s) { return overlap_area(s.apply(p1), p2); };
  double best = overlap(t);
  {
    // Centroid onto centroid first, when that overlaps more.
    Similarity2 moved = t;
    moved.translation = centroid2 - centroid1;
    const double area = overlap(moved);
    if (area > best) t = moved, best = area;
  }

  // Increases below this are rounding, not progress.
  const double noise = 1e-14 * area2;
  double step = initial_step * size;
  double turn = initial_turn_degrees * pi / 180.0;
  constexpr int moves = 10;  // 8 translations, 2 rotations
  for (int round = 0; round < max_rounds && step >= tolerance * size; ++round) {
    std::array<Similarity2, moves> tried;
    std::array<double, moves> area{};
    for (int k = 0; k < moves; ++k) {
      tried[k] = t;
      if (k < 8) {
        const double direction = k * pi / 4;
        tried[k].translation += step * Vec2(std::cos(direction), std::sin(direction));
      } else {
        tried[k].angle += k == 8 ? turn : -turn;
      }
    }
    tbb::parallel_for(0, moves, [&](int k) { area[k] = overlap(tried[k]); });
    int chosen = 0;
    for (int k = 1; k < moves; ++k) {
      if (area[k] > area[chosen]) chosen = k;
    }
    if (area[chosen] > best + noise) {
      t = tried[chosen];
      best = area[chosen];
    } else {
      step *= 0.5;
      turn *= 0.5;
    }
  }
  t.angle = std::remainder(t.angle, 2 * pi);
  return t;
}

}  // namespace

Points2 Similarity2::apply(const Points2Ref& points) const {
  const double c = scale * std::cos(angle), s = scale * std::sin(angle);
  const Vec2 to = centre + translation;
  Points2 out(points.rows(), 2);
  for (Index i = 0; i < points.rows(); ++i) {
    const double x = points(i, 0) - centre.x(), y = points(i, 1) - centre.y();
    out(i, 0) = to.x() + (c * x - s * y);
    out(i, 1) = to.y() + (s * x + c * y);
  }
  return out;
}

Points2 Similarity2::apply_inverse(const Points2Ref& points) const {
  if (!(scale != 0.0 && std::isfinite(scale))) {
    detail::invalid("scale", "the similarity has no inverse (scale " + std::to_string(scale) + ")");
  }
  const double c = std::cos(angle) / scale, s = std::sin(angle) / scale;
  const Vec2 from = centre + translation;
  Points2 out(points.rows(), 2);
  for (Index i = 0; i < points.rows(); ++i) {
    const double x = points(i, 0) - from.x(), y = points(i, 1) - from.y();
    out(i, 0) = centre.x() + (c * x + s * y);
    out(i, 1) = centre.y() + (-s * x + c * y);
  }
  return out;
}

Similarity2 align_curves(const Points2Ref& c1, const Points2Ref& c2, bool closed, double tolerance) {
  if (!(std::isfinite(tolerance) && tolerance > 0)) {
    detail::invalid("tolerance", "must be positive and finite, got " + std::to_string(tolerance));
  }
  return closed ? align_closed(c1, c2, tolerance) : align_open(c1, c2);
}

}  // namespace morphomap
