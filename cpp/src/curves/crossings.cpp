#include <morphomap/crossings.hpp>

#include "common/interrupt_check.hpp"
#include "common/segment_pairs.hpp"
#include "common/validation.hpp"
#include "curves/crossing_sweep.hpp"

#include <CGAL/Exact_predicates_exact_constructions_kernel.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <iterator>
#include <limits>
#include <optional>
#include <queue>
#include <set>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

// A sweep line (Bentley-Ottmann) over the segments: O((n + k) log n) for n segments and k meeting
// points, so that dense displacement fields, whose long and nearly parallel vectors have ~n²
// overlapping bounding boxes, stay fast. It is our own rather than CGAL's Surface_sweep_2
// (compute_subcurves, compute_intersection_points): in CGAL 5.5 that aborts with a precondition
// violation in Multiset.h (and in release builds misses pairs or crashes) on as few as the four
// segments (0,1)-(2,3), (3,1)-(0,3), (3,2)-(1,2), (1,3)-(2,1), even with an exact kernel.
//
// Events are points in lexicographic (x, y) order: the segments' end points (exact doubles) and
// the points where two neighbours cross properly (exact, Epeck). The status holds the segments
// that contain the sweep point's past and future, ordered along the sweep line just after the
// current event (a vertical segment comes after every other segment through the same point, as
// if the line were turned a little clockwise). At each event p the segments that contain p form
// one run of the status; with those that start or end at p and the zero-length ones at p, every
// pair that meets at p and for which p is their first common point is reported there:
//   - two segments through p (p inside both): a crossing unless they are collinear (then they
//     overlap and were reported where the overlap began);
//   - one through p, one starting at p: always (a T-junction, or a collinear overlap that begins
//     at p);
//   - one through p, one ending at p: unless collinear (the overlap began earlier);
//   - two starting at p: only if collinear, i.e. overlapping from p on (a shared start is not
//     a crossing otherwise); two ending at p, or one ending and one starting: never;
//   - a zero-length segment at p and one through p: always; with one ending or starting at p,
//     or another point: never.
// So pairs that only share an end point are never enumerated (a fan of vectors ending at one
// point costs a sort), and a collinear overlap is reported once, at its first point.

namespace morphomap {
namespace {

using Epick = CGAL::Exact_predicates_inexact_constructions_kernel;
using Epeck = CGAL::Exact_predicates_exact_constructions_kernel;
using Point = Epick::Point_2;
using ExactPoint = Epeck::Point_2;

ExactPoint exact(const Point& p) { return ExactPoint(p.x(), p.y()); }

bool lex_less(const Point& p, const Point& q) { return p.x() < q.x() || (p.x() == q.x() && p.y() < q.y()); }

struct Segments {
  // Finite rows only, with a <= b lexicographically; `row` gives the input row.
  std::vector<Point> a, b;
  std::vector<Index> row;
};

Segments read_segments(const Points2Ref& starts, const Points2Ref& ends) {
  if (starts.rows() != ends.rows()) {
    detail::invalid("ends",
                    "has " + std::to_string(ends.rows()) + " rows but starts has " + std::to_string(starts.rows()));
  }
  Segments s;
  const Index n = starts.rows();
  for (Index i = 0; i < n; ++i) {
    if (!(std::isfinite(starts(i, 0)) && std::isfinite(starts(i, 1)) && std::isfinite(ends(i, 0)) &&
          std::isfinite(ends(i, 1)))) {
      continue;
    }
    Point p(starts(i, 0), starts(i, 1)), q(ends(i, 0), ends(i, 1));
    if (lex_less(q, p)) std::swap(p, q);
    s.a.push_back(p);
    s.b.push_back(q);
    s.row.push_back(i);
  }
  return s;
}

// An end point event. Kinds sort so that, at one point, the events come grouped by kind.
enum Kind : std::uint8_t { kEnd = 0, kStart = 1, kPoint = 2 };
struct EndEvent {
  double x, y;
  std::uint32_t seg;
  Kind kind;
};

// A point where neighbours i < j cross properly.
struct Crossing {
  ExactPoint p;
  std::uint32_t i, j;
};

// The order of interval x, y against interval u, v, where certain: SMALLER, LARGER, or EQUAL
// for unknown.
template <class I>
CGAL::Comparison_result certain_xy(const I& x, const I& y, const I& u, const I& v) {
  if (x.sup() < u.inf()) return CGAL::SMALLER;
  if (x.inf() > u.sup()) return CGAL::LARGER;
  if (x.is_point() && u.is_point() && x.inf() == u.inf()) {
    if (y.sup() < v.inf()) return CGAL::SMALLER;
    if (y.inf() > v.sup()) return CGAL::LARGER;
  }
  return CGAL::EQUAL;
}

struct CrossingGreater {  // for a min-queue
  bool operator()(const Crossing& c, const Crossing& d) const {
    // The same pair again (neighbours can meet more than once): the same point, and no need to
    // compare equal exact points, which is slow.
    if (c.i == d.i && c.j == d.j) return false;
    const auto &p = c.p.approx(), &q = d.p.approx();
    const CGAL::Comparison_result r = certain_xy(p.x(), p.y(), q.x(), q.y());
    if (r != CGAL::EQUAL) return r == CGAL::LARGER;
    return CGAL::compare_xy(c.p, d.p) == CGAL::LARGER;
  }
};

// compare_xy(p, q) for a double point p, trying q's interval approximation first.
CGAL::Comparison_result compare_xy(const Point& p, const ExactPoint& q) {
  const auto& approx = q.approx();
  using I = std::decay_t<decltype(approx.x())>;
  const CGAL::Comparison_result r = certain_xy(I(p.x()), I(p.y()), approx.x(), approx.y());
  if (r != CGAL::EQUAL) return r;
  return CGAL::compare_xy(ExactPoint(p.x(), p.y()), q);
}

// Calls report(i, j) for every crossing pair, with i and j positions in s (each pair once).
template <class Report>
class Sweep {
 public:
  Sweep(const Segments& s, Report& report) : s_(s), report_(report), status_(Less{this}) {}

  void run() {
    const std::size_t n = s_.a.size();
    std::vector<EndEvent> events;
    events.reserve(2 * n);
    for (std::size_t i = 0; i < n; ++i) {
      const auto seg = static_cast<std::uint32_t>(i);
      if (s_.a[i] == s_.b[i]) {
        events.push_back({s_.a[i].x(), s_.a[i].y(), seg, kPoint});
      } else {
        events.push_back({s_.a[i].x(), s_.a[i].y(), seg, kStart});
        events.push_back({s_.b[i].x(), s_.b[i].y(), seg, kEnd});
      }
    }
    std::sort(events.begin(), events.end(), [](const EndEvent& e, const EndEvent& f) {
      if (e.x != f.x) return e.x < f.x;
      if (e.y != f.y) return e.y < f.y;
      return e.kind < f.kind;
    });
    end_mark_.assign(n, 0);
    side_mark_.assign(n, 0);
    side_value_.assign(n, 0);

    std::size_t next = 0;
    std::uint64_t step = 0;
    while (next < events.size() || !crossings_.empty()) {
      if ((++step & 0xffff) == 0) detail::check_interrupt();
      // The next event point: the smaller of the next end point and the next crossing point.
      ++stamp_;
      bool at_end_point = next < events.size();
      if (at_end_point && !crossings_.empty()) {
        at_end_point = compare_xy(Point(events[next].x, events[next].y), crossings_.top().p) != CGAL::LARGER;
      }
      ep_valid_ = false;
      if (at_end_point) {
        p_exact_ = false;
        p_ = Point(events[next].x, events[next].y);
        if (!crossings_.empty()) pop_crossings(exact_p(), false);
      } else {
        p_exact_ = true;
        ep_ = crossings_.top().p;
        pop_crossings(ep_, true);
      }
      ending_.clear();
      starting_.clear();
      points_.clear();
      if (at_end_point) {
        const double x = events[next].x, y = events[next].y;
        for (; next < events.size() && events[next].x == x && events[next].y == y; ++next) {
          const EndEvent& e = events[next];
          if (e.kind == kEnd) {
            ending_.push_back(e.seg);
            end_mark_[e.seg] = stamp_;
          } else if (e.kind == kStart) {
            starting_.push_back(e.seg);
          } else {
            points_.push_back(e.seg);
          }
        }
      }
      handle_event();
    }
  }

 private:
  // The status order, valid when one of the two segments contains the current event point
  // (std::set only compares the element being inserted, which does, with elements in the set).
  // The probe looks up the run of segments that contain the current event point.
  struct Probe {};
  struct Less {
    using is_transparent = void;
    const Sweep* sweep;
    bool operator()(std::uint32_t i, std::uint32_t j) const { return sweep->status_less(i, j); }
    bool operator()(std::uint32_t i, Probe) const { return sweep->side(i) < 0; }
    bool operator()(Probe, std::uint32_t i) const { return sweep->side(i) > 0; }
  };

  // Removes the queued crossings at p (the first one is p when p was taken from the queue);
  // their segments contain p.
  void pop_crossings(const ExactPoint& p, bool top_is_p) {
    bool have = false;
    std::uint32_t i = 0, j = 0;
    while (!crossings_.empty()) {
      const Crossing& c = crossings_.top();
      const bool at_p = have ? (c.i == i && c.j == j) || c.p == p : top_is_p || c.p == p;
      if (!at_p) break;
      have = true;
      i = c.i;
      j = c.j;
      set_side(i, 0);
      set_side(j, 0);
      crossings_.pop();
    }
  }
  void set_side(std::uint32_t i, int value) const {
    side_mark_[i] = stamp_;
    side_value_[i] = static_cast<std::int8_t>(value);
  }

  // Sign of (y of segment i at the sweep point's x) - (y of the sweep point): 0 if i contains
  // it (a vertical segment in the status always does). Remembered for the event.
  int side(std::uint32_t i) const {
    if (side_mark_[i] == stamp_) return side_value_[i];
    const Point &a = s_.a[i], &b = s_.b[i];
    const int value = p_exact_ ? -exact_orientation(a, b) : -static_cast<int>(CGAL::orientation(a, b, p_));
    set_side(i, value);
    return value;
  }
  // orientation(a, b, ep_), with a filter on ep_'s interval approximation first.
  int exact_orientation(const Point& a, const Point& b) const {
    {
      const auto& q = ep_.approx();
      using I = std::decay_t<decltype(q.x())>;
      CGAL::Protect_FPU_rounding<true> upward;
      const I ax(a.x()), ay(a.y());
      const I det = (I(b.x()) - ax) * (q.y() - ay) - (I(b.y()) - ay) * (q.x() - ax);
      if (det.inf() > 0) return 1;
      if (det.sup() < 0) return -1;
    }
    return static_cast<int>(CGAL::orientation(exact(a), exact(b), ep_));
  }
  // The event point as an exact point.
  const ExactPoint& exact_p() {
    if (!p_exact_ && !ep_valid_) ep_ = exact(p_);
    ep_valid_ = true;
    return ep_;
  }

  // Slope comparison, vertical the largest.
  int slope(std::uint32_t i, std::uint32_t j) const {
    const Point &a = s_.a[i], &b = s_.b[i], &c = s_.a[j], &d = s_.b[j];
    // Both run left to right (dx >= 0), so the slopes compare as the cross product
    // (b - a) x (d - c) < 0. Floating point with Shewchuk's orient2d error bound (the same form
    // of expression) first, CGAL's exact predicate when that cannot decide.
    const double left = (b.x() - a.x()) * (d.y() - c.y()), right = (b.y() - a.y()) * (d.x() - c.x());
    const double det = left - right, sum = std::abs(left) + std::abs(right);
    constexpr double eps = std::numeric_limits<double>::epsilon() / 2;
    constexpr double bound = (3.0 + 16.0 * eps) * eps;
    if (sum > 1e-280 && sum < 1e280 && std::abs(det) > bound * sum) return det > 0 ? -1 : 1;
    return static_cast<int>(CGAL::compare_slope(Epick::Segment_2(a, b), Epick::Segment_2(c, d)));
  }
  bool slope_less(std::uint32_t i, std::uint32_t j) const {
    const int c = slope(i, j);
    return c != 0 ? c < 0 : i < j;
  }
  bool status_less(std::uint32_t i, std::uint32_t j) const {
    if (i == j) return false;
    const int si = side(i), sj = side(j);
    if (si != sj) return si < sj;
    if (si == 0) return slope_less(i, j);
    // Not needed by the sweep (neither contains the event point); a consistent answer anyway.
    const Epeck::Segment_2 ei(exact(s_.a[i]), exact(s_.b[i])), ej(exact(s_.a[j]), exact(s_.b[j]));
    const ExactPoint p = p_exact_ ? ep_ : exact(p_);
    const int c = static_cast<int>(CGAL::compare_y_at_x(p, ei, ej));
    if (c != 0) return c < 0;
    const int d = slope(i, j);
    if (d != 0) return si < 0 ? d < 0 : d > 0;
    return i < j;
  }

  void handle_event() {
    // The run of status segments that contain p: those ending at p and those passing through.
    const auto lo = status_.lower_bound(Probe{});
    auto hi = lo;
    through_.clear();
    for (; hi != status_.end() && side(*hi) == 0; ++hi) {
      if (end_mark_[*hi] != stamp_) through_.push_back(*hi);
    }
    report_pairs();

    // Replace the run by the segments that continue to the right of p, in slope order.
    std::uint32_t below = 0;
    const bool has_below = lo != status_.begin();
    if (has_below) below = *std::prev(lo);
    status_.erase(lo, hi);
    continuing_.clear();
    continuing_.insert(continuing_.end(), through_.begin(), through_.end());
    continuing_.insert(continuing_.end(), starting_.begin(), starting_.end());
    std::sort(continuing_.begin(), continuing_.end(),
              [this](std::uint32_t i, std::uint32_t j) { return slope_less(i, j); });
    for (const std::uint32_t i : continuing_) status_.insert(hi, i);
    const bool has_above = hi != status_.end();
    if (continuing_.empty()) {
      if (has_below && has_above) test(below, *hi);
    } else {
      if (has_below) test(below, continuing_.front());
      if (has_above) test(continuing_.back(), *hi);
    }
  }

  void report_pairs() {
    // Through p, in slope order, grouped into runs of collinear segments.
    std::sort(through_.begin(), through_.end(), [this](std::uint32_t i, std::uint32_t j) { return slope_less(i, j); });
    for (std::size_t k = 0; k < through_.size();) {
      std::size_t end = k + 1;
      while (end < through_.size() && slope(through_[k], through_[end]) == 0) ++end;
      for (std::size_t i = k; i < end; ++i) {
        for (std::size_t j = end; j < through_.size(); ++j) report_(through_[i], through_[j]);
      }
      k = end;
    }
    for (const std::uint32_t c : through_) {
      for (const std::uint32_t t : starting_) report_(c, t);
      for (const std::uint32_t t : points_) report_(c, t);
    }
    if (!through_.empty() && !ending_.empty()) {
      std::sort(ending_.begin(), ending_.end(), [this](std::uint32_t i, std::uint32_t j) { return slope_less(i, j); });
      for (const std::uint32_t c : through_) {
        // The segments ending at p that are collinear with c: one run of ending_.
        const auto first =
            std::partition_point(ending_.begin(), ending_.end(), [&](std::uint32_t e) { return slope(e, c) < 0; });
        auto last = first;
        while (last != ending_.end() && slope(*last, c) == 0) ++last;
        for (auto e = ending_.begin(); e != first; ++e) report_(c, *e);
        for (auto e = last; e != ending_.end(); ++e) report_(c, *e);
      }
    }
    if (starting_.size() > 1) {
      std::sort(starting_.begin(), starting_.end(),
                [this](std::uint32_t i, std::uint32_t j) { return slope_less(i, j); });
      for (std::size_t k = 0; k < starting_.size();) {
        std::size_t end = k + 1;
        while (end < starting_.size() && slope(starting_[k], starting_[end]) == 0) ++end;
        for (std::size_t i = k; i < end; ++i) {
          for (std::size_t j = i + 1; j < end; ++j) report_(starting_[i], starting_[j]);
        }
        k = end;
      }
    }
  }

  // Neighbours i (below) and j (above) just after p: a crossing point after p becomes an event.
  // If they meet at an end point of either, that point is an event already.
  void test(std::uint32_t i, std::uint32_t j) {
    // Parallel segments never cross properly (collinear overlaps start at an end point).
    const Point &a = s_.a[i], &b = s_.b[i], &c = s_.a[j], &d = s_.b[j];
    const int o1 = static_cast<int>(CGAL::orientation(a, b, c)), o2 = static_cast<int>(CGAL::orientation(a, b, d));
    if (o1 * o2 >= 0) return;
    const int o3 = static_cast<int>(CGAL::orientation(c, d, a)), o4 = static_cast<int>(CGAL::orientation(c, d, b));
    if (o3 * o4 >= 0) return;
    const auto meet = CGAL::intersection(Epeck::Line_2(exact(a), exact(b)), Epeck::Line_2(exact(c), exact(d)));
    if (!meet) return;
    const ExactPoint* q = boost::get<ExactPoint>(&*meet);
    if (q == nullptr) return;
    if (CGAL::compare_xy(*q, exact_p()) == CGAL::LARGER) crossings_.push({*q, std::min(i, j), std::max(i, j)});
  }

 private:
  const Segments& s_;
  Report& report_;
  bool p_exact_ = false, ep_valid_ = false;
  Point p_;
  ExactPoint ep_;
  std::priority_queue<Crossing, std::vector<Crossing>, CrossingGreater> crossings_;
  std::vector<std::uint64_t> end_mark_;
  mutable std::vector<std::uint64_t> side_mark_;
  mutable std::vector<std::int8_t> side_value_;
  std::uint64_t stamp_ = 0;
  std::vector<std::uint32_t> ending_, starting_, points_, through_, continuing_;
  std::set<std::uint32_t, Less> status_;
};

template <class Report>
void sweep(const Segments& s, Report& report) {
  Sweep<Report>(s, report).run();
}

// Whether segments i and j (compact indices) have a common point other than a shared end point
// of both: the definition, pair by pair, for the box search below.
bool crossing(const Segments& s, std::size_t i, std::size_t j) {
  const Point &a = s.a[i], &b = s.b[i], &c = s.a[j], &d = s.b[j];
  if (!detail::segments_meet(a, b, c, d)) return false;
  const Point* x = nullptr;
  const Point *u = nullptr, *w = nullptr;
  if (a == c)
    x = &a, u = &b, w = &d;
  else if (a == d)
    x = &a, u = &b, w = &c;
  else if (b == c)
    x = &b, u = &a, w = &d;
  else if (b == d)
    x = &b, u = &a, w = &c;
  if (x == nullptr) return true;
  // A shared end point x: they meet elsewhere only if collinear and leaving x the same way.
  return detail::orient(*x, *u, *w) == 0 && CGAL::angle(*u, *x, *w) == CGAL::ACUTE;
}

struct Abandoned {};

// The box search tests every pair of segments whose bounding boxes overlap, on all cores: a few
// nanoseconds a pair, against the sweep's microseconds per crossing. It wins when crossings
// are a fair share of the overlapping boxes (a field that crosses a lot), and loses without
// bound when they are not (long, nearly parallel vectors overlap by the billion and cross
// nowhere). So it runs first and gives up once it has tested kProbe candidates of which fewer
// than one in kShare cross; the sweep then answers in O((n + k) log n).
constexpr std::size_t kProbe = std::size_t(1) << 22;
constexpr std::size_t kShare = 100;

// Returns the number of crossing pairs (and stores them in `kept` when given), or nothing when
// it gave up.
std::optional<Index> box_crossings(const Segments& s, detail::IndexPairs* kept) {
  std::vector<detail::SegmentBox> boxes;
  boxes.reserve(s.a.size());
  for (std::size_t i = 0; i < s.a.size(); ++i) boxes.emplace_back(s.a[i], s.b[i], i);
  detail::IndexPairs batch;
  std::vector<char> flags;
  std::size_t tested = 0, crossed = 0;
  auto flush = [&] {
    flags.assign(batch.size(), 0);
    tbb::parallel_for(std::size_t(0), batch.size(), [&](std::size_t k) {
      flags[k] = crossing(s, std::size_t(batch[k].first), std::size_t(batch[k].second)) ? 1 : 0;
    });
    for (std::size_t k = 0; k < batch.size(); ++k) {
      if (!flags[k]) continue;
      ++crossed;
      if (kept != nullptr) kept->push_back(batch[k]);
    }
    tested += batch.size();
    batch.clear();
    detail::check_interrupt();
    if (tested >= kProbe && crossed * kShare < tested) throw Abandoned();
  };
  try {
    CGAL::box_self_intersection_d(
        boxes.begin(), boxes.end(),
        [&](const detail::SegmentBox& p, const detail::SegmentBox& q) {
          batch.emplace_back(Index(p.index), Index(q.index));
          if (batch.size() == (std::size_t(1) << 20)) flush();
        },
        std::ptrdiff_t(10), CGAL::Box_intersection_d::CLOSED);
    flush();
  } catch (const Abandoned&) {
    if (kept != nullptr) kept->clear();
    return std::nullopt;
  }
  return Index(crossed);
}

}  // namespace

std::vector<std::pair<Index, Index>> crossing_pairs(const Points2Ref& starts, const Points2Ref& ends) {
  const Segments s = read_segments(starts, ends);
  std::vector<std::pair<Index, Index>> pairs;
  auto report = [&](std::uint32_t i, std::uint32_t j) {
    const Index r = s.row[i], t = s.row[j];
    pairs.emplace_back(std::min(r, t), std::max(r, t));
  };
  detail::IndexPairs found;
  if (box_crossings(s, &found)) {
    for (const auto& [i, j] : found) report(std::uint32_t(i), std::uint32_t(j));
  } else {
    sweep(s, report);
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

std::vector<std::pair<Index, Index>> detail::crossing_pairs_by_sweep(const Points2Ref& starts, const Points2Ref& ends) {
  const Segments s = read_segments(starts, ends);
  std::vector<std::pair<Index, Index>> pairs;
  auto report = [&](std::uint32_t i, std::uint32_t j) {
    pairs.emplace_back(std::min(s.row[i], s.row[j]), std::max(s.row[i], s.row[j]));
  };
  sweep(s, report);
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

Index count_crossings(const Points2Ref& starts, const Points2Ref& ends) {
  const Segments s = read_segments(starts, ends);
  if (const auto count = box_crossings(s, nullptr)) return *count;
  Index count = 0;
  auto report = [&](std::uint32_t, std::uint32_t) { ++count; };
  sweep(s, report);
  return count;
}

// The sweep alone: O(n log n) to the first crossing or to the end where there is none, which is
// the default's common case (a crossing-free candidate of 10^4 long vectors gives the box search
// millions of overlapping pairs to test; bench/README.md "Real 2D outlines").
bool detail::any_crossing(const Points2Ref& starts, const Points2Ref& ends) {
  struct FoundOne {};
  const Segments s = read_segments(starts, ends);
  auto stop = [](std::uint32_t, std::uint32_t) { throw FoundOne(); };
  try {
    sweep(s, stop);
  } catch (const FoundOne&) {
    return true;
  }
  return false;
}

}  // namespace morphomap
