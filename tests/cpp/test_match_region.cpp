// MatchRegion (the hard constraint of method "optimal", through its private header) against brute
// force: a vector is admitted exactly when no side of the region meets it between its ends and its
// midpoint lies inside the region, on random vectors between two wavy pieces (a polygon) and
// between two nested wavy closed curves (the ring cut along an anchor); regions that are not simple
// polygons are named.
#include "curves/inside.hpp"
#include "mapping/match_region.hpp"

#include "check.hpp"

#include <cmath>
#include <random>
#include <string>
#include <vector>

using morphomap::Index;
using morphomap::Points2;
using morphomap::Vec2;
using morphomap::detail::MatchRegion;

namespace {

double turn(const Vec2& a, const Vec2& b, const Vec2& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

// Closed segments ab and cd meet (no ties arise on the random vectors: plain doubles do).
bool meet(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const double d1 = turn(a, b, c), d2 = turn(a, b, d), d3 = turn(c, d, a), d4 = turn(c, d, b);
  return d1 * d2 <= 0.0 && d3 * d4 <= 0.0;
}

// Even-odd rule over the closed polylines `loops`: inside an odd number of them (the project's
// one-polygon test, not the code under test).
bool inside(const Vec2& p, const std::vector<Points2>& loops) {
  bool in = false;
  for (const Points2& loop : loops) in ^= morphomap::detail::inside(p, loop);
  return in;
}

// Brute force: the vector p -> q, shortened by 1e-7 of its length at both ends, meets none of the
// `sides` (closed polylines whose segments bound the region) and its midpoint is inside `loops`.
bool admitted(const Vec2& p, const Vec2& q, const std::vector<Points2>& sides, const std::vector<Points2>& loops) {
  const Vec2 a = p + 1e-7 * (q - p), b = q - 1e-7 * (q - p);
  for (const Points2& side : sides) {
    const Index n = side.rows();
    for (Index i = 0; i < n; ++i) {
      if (meet(a, b, side.row(i).transpose(), side.row((i + 1) % n).transpose())) return false;
    }
  }
  return inside(0.5 * (p + q), loops);
}

// A point at arc position s along the open polyline `curve`, with its segment.
Vec2 along(const Points2& curve, double s, Index& segment) {
  for (Index i = 0; i + 1 < curve.rows(); ++i) {
    const double length = (curve.row(i + 1) - curve.row(i)).norm();
    if (s <= length || i + 2 == curve.rows()) {
      segment = i;
      const double t = std::min(1.0, s / length);
      return (curve.row(i) + t * (curve.row(i + 1) - curve.row(i))).transpose();
    }
    s -= length;
  }
  segment = 0;
  return curve.row(0).transpose();
}

double length_of(const Points2& curve) {
  double sum = 0.0;
  for (Index i = 0; i + 1 < curve.rows(); ++i) sum += (curve.row(i + 1) - curve.row(i)).norm();
  return sum;
}

// Random vectors from the source's inner rows to the target; compares with brute force.
void compare(const Points2& source, const Points2& target, const std::vector<Points2>& sides,
             const std::vector<Points2>& loops, Index count) {
  const MatchRegion region(source, target);
  CHECK(region.why_not().empty());
  std::mt19937 random(7);
  std::uniform_int_distribution<Index> row(1, source.rows() - 2);
  std::uniform_real_distribution<double> arc(0.0, length_of(target));
  std::vector<Index> rows(count), segments(count);
  Points2 ends(count, 2);
  for (Index c = 0; c < count; ++c) {
    rows[c] = row(random);
    ends.row(c) = along(target, arc(random), segments[c]).transpose();
  }
  const std::vector<char> ok = region.admits(rows, ends, segments);
  Index agree = 0, in = 0;
  for (Index c = 0; c < count; ++c) {
    const bool truth = admitted(source.row(rows[c]).transpose(), ends.row(c).transpose(), sides, loops);
    agree += (ok[c] != 0) == truth;
    in += truth;
  }
  CHECK(agree == count);
  // Both answers are common, so that the comparison can fail either way.
  CHECK(in > count / 10 && in < count - count / 10);
}

Points2 wave(Index n, double x0, double x1, double y, double amplitude, double frequency) {
  Points2 out(n, 2);
  for (Index i = 0; i < n; ++i) {
    const double x = x0 + (x1 - x0) * static_cast<double>(i) / static_cast<double>(n - 1);
    out.row(i) << x, y + amplitude * std::sin(frequency * x);
  }
  return out;
}

// Two wavy open pieces: the polygon of source, end vector, target reversed and begin vector.
void polygon() {
  const Points2 source = wave(200, 0.0, 3.0, 0.0, 0.3, 5.0), target = wave(250, 0.0, 3.0, 1.0, 0.3, 7.0);
  Points2 outline(450, 2);
  outline << source, target.colwise().reverse();
  compare(source, target, {outline}, {outline}, 20000);
}

// A wavy closed curve r = radius + amplitude sin(frequency t), from angle 0 once round and back to
// its first point.
Points2 ring(Index n, double radius, double amplitude, double frequency) {
  Points2 out(n + 1, 2);
  for (Index i = 0; i <= n; ++i) {
    const double t = 2.0 * M_PI * static_cast<double>(i % n) / static_cast<double>(n);
    const double r = radius + amplitude * std::sin(frequency * t);
    out.row(i) << r * std::cos(t), r * std::sin(t);
  }
  return out;
}

// Nested wavy closed curves cut along the anchor at angle 0.
void cut_ring() {
  const Points2 source = ring(300, 1.0, 0.2, 5.0), target = ring(400, 2.0, 0.3, 7.0);
  Points2 anchor(2, 2);
  anchor << source.row(0), target.row(0);
  const Points2 inner = source.topRows(300), outer = target.topRows(400);
  compare(source, target, {inner, outer, anchor}, {inner, outer}, 20000);
}

void not_simple() {
  // The target's direction reversed: the vectors joining the pieces' ends cross.
  const Points2 source = wave(50, 0.0, 3.0, 0.0, 0.3, 5.0), target = wave(60, 3.0, 0.0, 1.0, 0.3, 7.0);
  CHECK(MatchRegion(source, target).why_not().find("simple polygon") != std::string::npos);
  // Two closed curves side by side.
  Points2 beside = ring(300, 1.0, 0.2, 5.0);
  beside.col(0).array() += 5.0;
  CHECK(MatchRegion(ring(200, 1.0, 0.2, 5.0), beside).why_not().find("inside the other") != std::string::npos);
  // An anchor that leaves the ring: cut where it runs through the inner curve.
  Points2 outer = ring(400, 2.0, 0.3, 7.0);
  outer = Points2(outer.colwise().reverse());  // starts at angle 0 as well, the other way round
  Points2 shifted(401, 2);
  for (Index i = 0; i <= 400; ++i) shifted.row(i) = outer.row((i + 200) % 400);  // from angle pi
  CHECK(MatchRegion(ring(300, 1.0, 0.2, 5.0), shifted).why_not().find("anchor") != std::string::npos);
}

}  // namespace

int main() {
  polygon();
  cut_ring();
  not_simple();
  TEST_MAIN_END();
}
