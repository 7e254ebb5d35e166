#pragma once
// Where the rows of a curve go when exact consecutive repeats are dropped (as
// detail::without_repeats does), so that results can be reported per input row or per input
// segment.
#include <morphomap/types.hpp>

#include <vector>

namespace morphomap::detail {

struct DistinctPoints {
  std::vector<Index> of_row;   // for each of the curve's rows, its point in the curve without repeats
  std::vector<Index> segment;  // for each point without repeats, the input segment that leaves it
};

// rows: the rows that take part (detail::curve_size). Matches detail::without_repeats.
inline DistinctPoints distinct_points(const Points2Ref& points, Index rows, bool closed) {
  DistinctPoints d;
  d.of_row.assign(rows, 0);
  for (Index r = 1; r < rows; ++r) {
    d.of_row[r] = d.of_row[r - 1] + (points.row(r) != points.row(r - 1) ? 1 : 0);
  }
  Index m = rows > 0 ? d.of_row[rows - 1] + 1 : 0;
  // A closed curve whose last distinct point is its first one again: that point is point 0.
  if (closed && m > 1 && points.row(rows - 1) == points.row(0)) {
    for (Index r = rows - 1; d.of_row[r] == m - 1; --r) d.of_row[r] = 0;
    --m;
  }
  // The segment leaving a point starts at the last row of the point's first run of repeats.
  d.segment.assign(m, -1);
  for (Index r = 0; r < rows; ++r) {
    const Index k = d.of_row[r];
    const bool run_ends = r + 1 == rows || d.of_row[r + 1] != k;
    if (run_ends && d.segment[k] < 0) d.segment[k] = r;
  }
  return d;
}

}  // namespace morphomap::detail
