#include <morphomap/curve_geometry.hpp>

#include "common/distinct_points.hpp"
#include "common/segment_pairs.hpp"
#include "common/validation.hpp"
#include "curves/unchecked.hpp"

#include <CGAL/Interval_nt.h>
#include <CGAL/MP_Float.h>

#include <cmath>
#include <cstdio>

namespace morphomap {
namespace {

double distance(const Points2Ref& p, Index i, Index j) { return std::hypot(p(j, 0) - p(i, 0), p(j, 1) - p(i, 1)); }

// Exact sign of the shoelace sum over the first n rows. The interval sum decides nearly always;
// MP_Float (exact for sums of products of doubles) settles the rest.
int area_sign(const Points2Ref& p, Index n) {
  {
    using I = CGAL::Interval_nt<false>;
    CGAL::Protect_FPU_rounding<true> rounding;
    I sum(0);
    for (Index i = 0; i < n; ++i) {
      const Index j = (i + 1) % n;
      sum += I(p(i, 0)) * I(p(j, 1)) - I(p(j, 0)) * I(p(i, 1));
    }
    if (sum.inf() > 0) return 1;
    if (sum.sup() < 0) return -1;
  }
  CGAL::MP_Float sum(0);
  for (Index i = 0; i < n; ++i) {
    const Index j = (i + 1) % n;
    sum += CGAL::MP_Float(p(i, 0)) * CGAL::MP_Float(p(j, 1)) - CGAL::MP_Float(p(j, 0)) * CGAL::MP_Float(p(i, 1));
  }
  return static_cast<int>(CGAL::sign(sum));
}

int closed_orientation(const Points2Ref& points, Index n) {
  const int sign = area_sign(points, n);
  if (sign == 0) detail::invalid("points", "the closed curve encloses zero area, so it has no orientation");
  return sign;
}

}  // namespace

Vector arc_lengths(const Points2Ref& points, bool closed) {
  detail::require_curve(points, closed, "points");
  Vector s(points.rows());
  s(0) = 0.0;
  for (Index i = 1; i < points.rows(); ++i) s(i) = s(i - 1) + distance(points, i - 1, i);
  return s;
}

double perimeter(const Points2Ref& points, bool closed) {
  detail::require_curve(points, closed, "points");
  return detail::perimeter_unchecked(points, closed);
}

double signed_area(const Points2Ref& points) {
  detail::require_curve(points, true, "points");
  return detail::signed_area_unchecked(points);
}

int orientation(const Points2Ref& points) {
  detail::require_curve(points, true, "points");
  return detail::orientation_unchecked(points);
}

Points2 normals(const Points2Ref& points, bool closed) {
  detail::require_curve(points, closed, "points");
  return detail::normals_unchecked(points, closed);
}

namespace detail {

double perimeter_unchecked(const Points2Ref& points, bool closed) {
  const Index n = curve_size(points, closed);
  double length = 0.0;
  for (Index i = 1; i < n; ++i) length += distance(points, i - 1, i);
  if (closed) length += distance(points, n - 1, 0);
  return length;
}

double signed_area_unchecked(const Points2Ref& points) {
  const Index n = curve_size(points, true);
  // Relative to the first point, so that a curve far from the origin loses no digits.
  const double x0 = points(0, 0), y0 = points(0, 1);
  double twice = 0.0;
  for (Index i = 1; i + 1 < n; ++i) {
    twice += (points(i, 0) - x0) * (points(i + 1, 1) - y0) - (points(i + 1, 0) - x0) * (points(i, 1) - y0);
  }
  return 0.5 * twice;
}

int orientation_unchecked(const Points2Ref& points) { return closed_orientation(points, curve_size(points, true)); }

Points2 normals_unchecked(const Points2Ref& points, bool closed) {
  const Points2 q = drop_repeats(points, closed, "points");
  const Index n = curve_size(points, closed);
  const Index m = q.rows();
  // Outward is to the right of travel on a counter-clockwise curve.
  const double side = closed ? closed_orientation(q, m) : 1.0;
  const Index segments = closed ? m : m - 1;

  Points2 right(segments, 2);  // unit normal of each segment, to the right of travel
  for (Index k = 0; k < segments; ++k) {
    const Vec2 d = q.row((k + 1) % m) - q.row(k);
    right.row(k) = Vec2(d.y(), -d.x()) / d.norm();
  }
  Points2 at(m, 2);
  for (Index k = 0; k < m; ++k) {
    const bool has_in = closed || k > 0, has_out = closed || k < m - 1;
    const Index in = (k + segments - 1) % segments;
    Vec2 sum = Vec2::Zero();
    if (has_in) sum += right.row(in).transpose();
    if (has_out) sum += right.row(k).transpose();
    const double length = sum.norm();
    if (length > 0) {
      at.row(k) = side * sum / length;
    } else {
      // The curve turns straight back here: the normal points along the incoming segment.
      const Vec2 d = q.row(k) - q.row((k + m - 1) % m);
      at.row(k) = d / d.norm();
    }
  }

  const detail::DistinctPoints distinct = detail::distinct_points(points, n, closed);
  Points2 out(points.rows(), 2);
  for (Index r = 0; r < points.rows(); ++r) {
    out.row(r) = at.row(r < n ? distinct.of_row[r] : 0);  // a dropped closing repeat is point 0
  }
  return out;
}

}  // namespace detail

namespace {

// Pairs of segments (i < j, of the curve without consecutive repeats q) that meet other than
// neighbours at their shared point: their number and, given `kept`, the pairs.
Index self_intersecting_pairs(const Points2& q, bool closed, detail::IndexPairs* kept) {
  const Index m = q.rows();
  const Index segments = closed ? m : m - 1;
  std::vector<detail::Point> p(m);
  for (Index k = 0; k < m; ++k) p[k] = detail::point_at(q, k);

  std::vector<detail::SegmentBox> boxes;
  boxes.reserve(segments);
  for (Index k = 0; k < segments; ++k) boxes.emplace_back(p[k], p[(k + 1) % m], k);

  const auto hit = [&](Index i, Index j) {  // i < j
    const bool next = j == i + 1, wraps = closed && i == 0 && j == segments - 1;
    if (next || wraps) {
      // Neighbours a -> b -> c share b; they meet elsewhere only when c folds back along ba.
      const Index b = wraps ? 0 : j;
      const detail::Point& pa = p[(b + m - 1) % m];
      const detail::Point& pc = p[(b + 1) % m];
      return detail::orient(pa, p[b], pc) == 0 && CGAL::angle(pa, p[b], pc) == CGAL::ACUTE;
    }
    return detail::segments_meet(p[i], p[(i + 1) % m], p[j], p[(j + 1) % m]);
  };
  return detail::test_overlapping_pairs(boxes, hit, kept);
}

}  // namespace

bool is_self_intersecting(const Points2Ref& points, bool closed) {
  return self_intersecting_pairs(detail::without_repeats(points, closed, "points"), closed, nullptr) > 0;
}

namespace detail {

void require_no_self_intersection(const Points2Ref& points, bool closed, const char* name) {
  const Points2 q = drop_repeats(points, closed, name);
  IndexPairs pairs;
  const Index count = self_intersecting_pairs(q, closed, &pairs);
  if (count == 0) return;
  const Index i = pairs.front().first, j = pairs.front().second;
  char where[96];
  std::snprintf(where, sizeof where, "(%.6g, %.6g) and (%.6g, %.6g)", q(i, 0), q(i, 1), q(j, 0), q(j, 1));
  invalid(name, "the curve intersects itself: " + std::to_string(count) + " pair" + (count == 1 ? "" : "s") +
                    " of its segments meet, the first at the segments starting at " + where +
                    "; the mapping needs a simple curve");
}

}  // namespace detail

}  // namespace morphomap
