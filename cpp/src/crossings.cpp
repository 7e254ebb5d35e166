#include <morphomap/crossings.hpp>

#include "segment_pairs.hpp"
#include "validation.hpp"

#include <cmath>
#include <string>

namespace morphomap {
namespace {

using detail::orient;
using detail::Point;

struct Segments {
  std::vector<Point> a, b;
  std::vector<detail::SegmentBox> boxes;  // only the rows with finite coordinates
};

Segments read_segments(const Points2Ref& starts, const Points2Ref& ends) {
  if (starts.rows() != ends.rows()) {
    detail::invalid("ends", "has " + std::to_string(ends.rows()) + " rows but starts has " +
                                std::to_string(starts.rows()));
  }
  Segments s;
  const Index n = starts.rows();
  s.a.resize(n);
  s.b.resize(n);
  for (Index i = 0; i < n; ++i) {
    if (!(std::isfinite(starts(i, 0)) && std::isfinite(starts(i, 1)) && std::isfinite(ends(i, 0)) &&
          std::isfinite(ends(i, 1)))) {
      continue;
    }
    s.a[i] = detail::point_at(starts, i);
    s.b[i] = detail::point_at(ends, i);
    s.boxes.emplace_back(s.a[i], s.b[i], i);
  }
  return s;
}

// Whether segments i and j have a common point other than a shared end point of both.
bool crossing(const Segments& s, Index i, Index j) {
  const Point &a = s.a[i], &b = s.b[i], &c = s.a[j], &d = s.b[j];
  if (!detail::segments_meet(a, b, c, d)) return false;
  // A shared end point x: the segments x-u and x-w meet only there unless they lie on one line
  // and leave x in the same direction.
  const Point* x = nullptr;
  const Point *u = nullptr, *w = nullptr;
  if (a == c) x = &a, u = &b, w = &d;
  else if (a == d) x = &a, u = &b, w = &c;
  else if (b == c) x = &b, u = &a, w = &d;
  else if (b == d) x = &b, u = &a, w = &c;
  if (x == nullptr) return true;
  return orient(*x, *u, *w) == 0 && CGAL::angle(*u, *x, *w) == CGAL::ACUTE;
}

}  // namespace

std::vector<std::pair<Index, Index>> crossing_pairs(const Points2Ref& starts, const Points2Ref& ends) {
  const Segments s = read_segments(starts, ends);
  detail::IndexPairs pairs;
  detail::test_overlapping_pairs(s.boxes, [&](Index i, Index j) { return crossing(s, i, j); }, &pairs);
  return pairs;
}

Index count_crossings(const Points2Ref& starts, const Points2Ref& ends) {
  const Segments s = read_segments(starts, ends);
  return detail::test_overlapping_pairs(s.boxes, [&](Index i, Index j) { return crossing(s, i, j); });
}

}  // namespace morphomap
