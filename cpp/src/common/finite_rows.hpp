#pragma once
// Batch queries over the rows that have an answer: rows with a NaN (a miss) are left out of the
// query and keep their place.
#include <morphomap/types.hpp>

#include <vector>

namespace morphomap::detail {

// The rows of `points` with every coordinate finite, in order.
template <class Matrix>
std::vector<Index> finite_rows(const Matrix& points) {
  std::vector<Index> rows;
  for (Index i = 0; i < points.rows(); ++i) {
    if (points.row(i).allFinite()) rows.push_back(i);
  }
  return rows;
}

}  // namespace morphomap::detail
