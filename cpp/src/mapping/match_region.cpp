// Which vectors lie inside the region between two pieces: a line query along each vector (from
// its midpoint, the nearest boundary point must be one of its ends) and exact orientation tests
// at both ends (the vector leaves each curve into the region, not along it or out of it).
#include "mapping/match_region.hpp"

#include <morphomap/curve_geometry.hpp>
#include <morphomap/errors.hpp>

#include "common/segment_pairs.hpp"
#include "curves/inside.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <cmath>
#include <string>
#include <tuple>
#include <vector>

namespace morphomap::detail {

namespace {

constexpr double kEndWindow = 1e-9;  // a boundary point this close (relative) to an end is that end

Points2 boundary_of(const Points2Ref& source, const Points2Ref& target) {
  Points2 b(source.rows() + target.rows(), 2);
  b.topRows(source.rows()) = source;
  b.bottomRows(target.rows()) = target.colwise().reverse();
  return b;
}

Point at(const Points2& points, Index i) { return Point(points(i, 0), points(i, 1)); }
Point at(const Vec2& p) { return Point(p.x(), p.y()); }

bool is_ring(const Points2Ref& source, const Points2Ref& target) {
  return source.rows() > 3 && target.rows() > 3 && source.row(0) == source.row(source.rows() - 1) &&
         target.row(0) == target.row(target.rows() - 1);
}

// Closed segments ab and cd, which share the end point a == c, meet elsewhere: one runs along the
// other from the shared point.
bool overlap_from_shared(const Point& a, const Point& b, const Point& d) {
  return orient(a, b, d) == 0 && (on_collinear_segment(a, b, d) || on_collinear_segment(a, d, b));
}

std::vector<SegmentBox> boxes_of(const Points2Ref& loop) {
  std::vector<SegmentBox> boxes;
  const Index m = loop.rows();
  for (Index k = 0; k < m; ++k) boxes.emplace_back(point_at(loop, k), point_at(loop, (k + 1) % m), k);
  return boxes;
}

}  // namespace

MatchRegion::MatchRegion(const Points2Ref& source, const Points2Ref& target)
    : boundary_(boundary_of(source, target)),
      source_rows_(source.rows()),
      target_rows_(target.rows()),
      index_(boundary_, true) {
  const Index m = boundary_.rows();
  previous_.resize(m), next_.resize(m);
  for (Index v = 0; v < m; ++v) {
    Index a = (v + m - 1) % m, b = (v + 1) % m;
    while (a != v && boundary_.row(a) == boundary_.row(v)) a = (a + m - 1) % m;
    while (b != v && boundary_.row(b) == boundary_.row(v)) b = (b + 1) % m;
    previous_[v] = a, next_[v] = b;
  }
  // Twice the signed area: for a ring cut open it is the source's minus the target's (the anchor
  // cancels), whose sign tells the side just as for a polygon when the curves are nested.
  double area = 0.0;
  for (Index v = 0; v < m; ++v) {
    const Index w = (v + 1) % m;
    area += boundary_(v, 0) * boundary_(w, 1) - boundary_(w, 0) * boundary_(v, 1);
  }
  side_ = area >= 0.0 ? 1 : -1;
  why_not_ = is_ring(source, target) ? check_ring(source, target) : check_polygon();
  if (why_not_.empty() && area == 0.0) why_not_ = "the region between the pieces has no area";
}

std::string MatchRegion::check_polygon() const {
  try {
    if (is_self_intersecting(boundary_, true)) {
      return "the pieces and the vectors joining their ends do not bound a simple polygon";
    }
  } catch (const InvalidInput&) {  // fewer than three distinct points
    return "the pieces and the vectors joining their ends do not bound a polygon";
  }
  return {};
}

std::string MatchRegion::check_ring(const Points2Ref& source, const Points2Ref& target) const {
  const Points2 s = source.topRows(source.rows() - 1), t = target.topRows(target.rows() - 1);
  try {
    if (is_self_intersecting(s, true) || is_self_intersecting(t, true)) return "a curve intersects itself";
  } catch (const InvalidInput&) {
    return "a curve has fewer than three distinct points";
  }
  const auto meet = [&](Index i, Index j) {
    return segments_meet(point_at(s, i), point_at(s, (i + 1) % s.rows()), point_at(t, j),
                         point_at(t, (j + 1) % t.rows()));
  };
  if (test_overlapping_pairs(boxes_of(s), boxes_of(t), meet) > 0) return "the two curves meet";
  const Vec2 s0 = s.row(0).transpose(), t0 = t.row(0).transpose();
  if (!inside(s0, t) && !inside(t0, s)) return "neither curve lies inside the other";
  // The anchor meets each curve at its own end only.
  const Point a = at(s0), b = at(t0);
  for (const auto& [loop, end, other] : {std::tuple(&s, a, b), std::tuple(&t, b, a)}) {
    const Index n = loop->rows();
    for (Index k = 0; k < n; ++k) {
      const Point c = point_at(*loop, k), d = point_at(*loop, (k + 1) % n);
      const bool bad = c == end   ? overlap_from_shared(end, other, d)
                       : d == end ? overlap_from_shared(end, other, c)
                                  : segments_meet(end, other, c, d);
      if (bad) return "the anchor vector meets a curve away from its ends";
    }
  }
  return {};
}

bool MatchRegion::into_at_vertex(Index v, const Vec2& x) const {
  const Point a = at(boundary_, previous_[v]), p = at(boundary_, v), b = at(boundary_, next_[v]), q = at(x);
  const int turn = side_ * orient(a, p, b), in_from = side_ * orient(a, p, q), in_to = side_ * orient(p, b, q);
  if (turn > 0) return in_from > 0 && in_to > 0;  // a corner the region lies inside of
  if (turn < 0) return in_from > 0 || in_to > 0;  // a corner the region wraps round
  // Straight on: the region's side. Straight back (a spike): nothing points in.
  const bool ahead = (p.x() - a.x()) * (b.x() - p.x()) + (p.y() - a.y()) * (b.y() - p.y()) > 0.0;
  return ahead && in_from > 0;
}

std::vector<char> MatchRegion::admits(const std::vector<Index>& rows, const Points2& ends,
                                      const std::vector<Index>& segments) const {
  const Index count = static_cast<Index>(rows.size());
  std::vector<char> ok(count, 0);
  if (count == 0) return ok;
  // Ends: exact tests; the rest goes to one batch of line queries.
  std::vector<Index> queried;
  tbb::parallel_for(tbb::blocked_range<Index>(0, count, 1024), [&](const tbb::blocked_range<Index>& range) {
    for (Index c = range.begin(); c < range.end(); ++c) {
      const Vec2 p = boundary_.row(rows[c]).transpose(), q = ends.row(c).transpose();
      if (p == q) {
        ok[c] = 1;
        continue;
      }
      if (!into_at_vertex(rows[c], q)) continue;
      // q on target segment j: a vertex, or inside the segment (which the boundary runs along
      // from row j + 1 to row j).
      const Index j = segments[c];
      const Index k = (j + 1) % target_rows_;
      if (q == boundary_.row(target_vertex(j)).transpose()) {
        ok[c] = into_at_vertex(target_vertex(j), p);
      } else if (q == boundary_.row(target_vertex(k)).transpose()) {
        ok[c] = into_at_vertex(target_vertex(k), p);
      } else {
        ok[c] = side_ * orient(at(boundary_, target_vertex(k)), at(boundary_, target_vertex(j)), at(p)) > 0;
      }
    }
  });
  for (Index c = 0; c < count; ++c) {
    if (ok[c] && boundary_.row(rows[c]) != ends.row(c)) queried.push_back(c);
  }
  const Index m = static_cast<Index>(queried.size());
  Points2 origins(m, 2), directions(m, 2);
  for (Index r = 0; r < m; ++r) {
    const Index c = queried[r];
    const Vec2 p = boundary_.row(rows[c]).transpose(), q = ends.row(c).transpose();
    origins.row(r) = (0.5 * (p + q)).transpose();
    directions.row(r) = (q - p).transpose();
  }
  const CurveHits hits = index_.line_intersections(origins, directions);
  for (Index r = 0; r < m; ++r) {
    const double half = 0.5 * directions.row(r).norm();
    // The nearest boundary point along the line: an end of the vector (|t| = half) or, strictly
    // inside it, a point where it leaves the region.
    if (std::abs(hits.distances[r]) < half * (1.0 - kEndWindow)) ok[queried[r]] = 0;
  }
  return ok;
}

}  // namespace morphomap::detail
