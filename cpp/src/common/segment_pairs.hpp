#pragma once
// Shared by the segment-intersection kernels (is_self_intersecting, curve_intersections,
// crossings): exact predicates on double coordinates and the search for candidate segment pairs
// whose closed bounding boxes overlap.
#include <morphomap/types.hpp>

#include "common/interrupt_check.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/box_intersection_d.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cstddef>
#include <utility>
#include <vector>

namespace morphomap::detail {

using Kernel = CGAL::Exact_predicates_inexact_constructions_kernel;
using Point = Kernel::Point_2;

inline Point point_at(const Points2Ref& points, Index i) { return Point(points(i, 0), points(i, 1)); }

// Exact sign of the turn a -> b -> c: +1 left, -1 right, 0 collinear.
inline int orient(const Point& a, const Point& b, const Point& c) {
  return static_cast<int>(CGAL::orientation(a, b, c));
}

// For c collinear with a and b: whether c lies on the closed segment ab. Comparing coordinates
// is exact, and for collinear points the bounding box test is the segment test.
inline bool on_collinear_segment(const Point& a, const Point& b, const Point& c) {
  return std::min(a.x(), b.x()) <= c.x() && c.x() <= std::max(a.x(), b.x()) && std::min(a.y(), b.y()) <= c.y() &&
         c.y() <= std::max(a.y(), b.y());
}

// Whether the closed segments ab and cd have a point in common; either may be a single point.
inline bool segments_meet(const Point& a, const Point& b, const Point& c, const Point& d) {
  const int o1 = orient(a, b, c), o2 = orient(a, b, d);
  const int o3 = orient(c, d, a), o4 = orient(c, d, b);
  if (o1 * o2 < 0 && o3 * o4 < 0) return true;
  // Otherwise they can only meet at an end point lying on the other segment. orient() of a
  // degenerate segment is 0 for every point, so points are handled too.
  return (o1 == 0 && on_collinear_segment(a, b, c)) || (o2 == 0 && on_collinear_segment(a, b, d)) ||
         (o3 == 0 && on_collinear_segment(c, d, a)) || (o4 == 0 && on_collinear_segment(c, d, b));
}

// The closed bounding box of a segment, in the form CGAL's box intersection expects. The id must
// be unique across both sets of a bipartite search: CGAL skips pairs with equal ids.
struct SegmentBox {
  using NT = double;
  using ID = std::size_t;
  double lo[2], hi[2];
  std::size_t index;

  SegmentBox(const Point& a, const Point& b, std::size_t i)
      : lo{std::min(a.x(), b.x()), std::min(a.y(), b.y())},
        hi{std::max(a.x(), b.x()), std::max(a.y(), b.y())},
        index(i) {}
  static int dimension() { return 2; }
  double min_coord(int d) const { return lo[d]; }
  double max_coord(int d) const { return hi[d]; }
  std::size_t id() const { return index; }
};

using IndexPairs = std::vector<std::pair<Index, Index>>;

// Collects candidate pairs from a box search and tests them on all cores in batches, so that
// memory stays bounded however many boxes overlap (long vectors of a dense field overlap by the
// million). Counts the pairs for which keep(i, j) holds and, given `kept`, stores them sorted.
template <class Keep>
class PairTester {
 public:
  PairTester(const Keep& keep, IndexPairs* kept) : keep_(keep), kept_(kept) { batch_.reserve(batch_size); }
  void add(Index i, Index j) {
    batch_.emplace_back(i, j);
    if (batch_.size() == batch_size) flush();
    if ((batch_.size() & 0xffff) == 0) check_interrupt();
  }
  Index finish() {
    flush();
    if (kept_ != nullptr) std::sort(kept_->begin(), kept_->end());
    return count_;
  }

 private:
  static constexpr std::size_t batch_size = std::size_t(1) << 20;
  void flush() {
    flags_.assign(batch_.size(), 0);
    tbb::parallel_for(std::size_t(0), batch_.size(),
                      [&](std::size_t k) { flags_[k] = keep_(batch_[k].first, batch_[k].second) ? 1 : 0; });
    for (std::size_t k = 0; k < batch_.size(); ++k) {
      if (!flags_[k]) continue;
      ++count_;
      if (kept_ != nullptr) kept_->push_back(batch_[k]);
    }
    batch_.clear();
  }
  const Keep& keep_;
  IndexPairs* kept_;
  IndexPairs batch_;
  std::vector<char> flags_;
  Index count_ = 0;
};

// Pairs (i < j) of overlapping boxes (closed: touching counts) for which keep(i, j) holds:
// returns their number and, given `kept`, stores them sorted. keep runs concurrently.
template <class Keep>
Index test_overlapping_pairs(std::vector<SegmentBox> boxes, const Keep& keep, IndexPairs* kept = nullptr) {
  PairTester<Keep> tester(keep, kept);
  // Each overlapping pair is reported once.
  CGAL::box_self_intersection_d(
      boxes.begin(), boxes.end(),
      [&](const SegmentBox& a, const SegmentBox& b) {
        const Index i = static_cast<Index>(a.index), j = static_cast<Index>(b.index);
        tester.add(std::min(i, j), std::max(i, j));
      },
      std::ptrdiff_t(10), CGAL::Box_intersection_d::CLOSED);
  return tester.finish();
}

// The same for pairs (i, j), box i of `first` overlapping box j of `second`; the boxes' index
// fields are positions in their own set.
template <class Keep>
Index test_overlapping_pairs(std::vector<SegmentBox> first, std::vector<SegmentBox> second, const Keep& keep,
                             IndexPairs* kept = nullptr) {
  const std::size_t offset = first.size();
  for (SegmentBox& box : second) box.index += offset;
  PairTester<Keep> tester(keep, kept);
  CGAL::box_intersection_d(
      first.begin(), first.end(), second.begin(), second.end(),
      [&](const SegmentBox& a, const SegmentBox& b) {
        tester.add(static_cast<Index>(a.index), static_cast<Index>(b.index - offset));
      },
      std::ptrdiff_t(10), CGAL::Box_intersection_d::CLOSED);
  return tester.finish();
}

}  // namespace morphomap::detail
