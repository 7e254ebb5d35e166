#pragma once
// P1 assembly of a Dirichlet problem's system on its free vertices, straight into compressed
// columns and in parallel (TBB): each column is gathered from the elements around its vertex, so
// no thread writes another's entries, and each entry sums its elements' contributions in element
// order, so the matrix is the same bits on any number of threads, and the same bits as
// setFromTriplets on the triplets in element order (without their memory and their sort).
#include <morphomap/types.hpp>

#include <Eigen/SparseCore>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <utility>
#include <vector>

namespace morphomap::detail {

// The matrix on the free vertices (unknown[v]: v's free index, -1 for a fixed vertex; both
// triangles stored) and the right-hand side, minus the fixed vertices' `values` times their
// couplings. elements: (E, K) vertex indices; local(e): element e's K x K matrix.
template <class Elements, class Local>
void assemble_free(const Elements& elements, const Local& local, const std::vector<Index>& unknown, Index free_count,
                   const Eigen::MatrixXd& values, Eigen::SparseMatrix<double>& matrix, Eigen::MatrixXd& rhs) {
  const Index element_count = elements.rows();
  const int corners = static_cast<int>(elements.cols());
  const int block = corners * corners;
  // Every local matrix once, row-major (half the memory of the triplets they used to become).
  // With them, each corner's free index (-1: fixed), so that a gather reads one place per element.
  std::vector<double> locals(element_count * block);
  std::vector<int> free_corner(element_count * corners);
  tbb::parallel_for(tbb::blocked_range<Index>(0, element_count, 1024), [&](const tbb::blocked_range<Index>& range) {
    for (Index e = range.begin(); e < range.end(); ++e) {
      for (int i = 0; i < corners; ++i) free_corner[e * corners + i] = static_cast<int>(unknown[elements(e, i)]);
      const auto k = local(e);
      for (int i = 0; i < corners; ++i) {
        for (int j = 0; j < corners; ++j) locals[e * block + i * corners + j] = k(i, j);
      }
    }
  });
  // The (element, corner) pairs around each free vertex, as element * corners + corner, in element order.
  std::vector<Index> first(free_count + 1, 0);
  for (Index e = 0; e < element_count; ++e) {
    for (int i = 0; i < corners; ++i) {
      const Index u = unknown[elements(e, i)];
      if (u >= 0) ++first[u + 1];
    }
  }
  for (Index u = 0; u < free_count; ++u) first[u + 1] += first[u];
  std::vector<Index> around(first[free_count]), next(first.begin(), first.end() - 1);
  for (Index e = 0; e < element_count; ++e) {
    for (int i = 0; i < corners; ++i) {
      const Index u = unknown[elements(e, i)];
      if (u >= 0) around[next[u]++] = e * corners + i;
    }
  }
  // Per thread: the column that last saw each row, and where its entry is.
  struct Seen {
    int column = -1, slot = 0;
  };
  tbb::enumerable_thread_specific<std::vector<Seen>> scratch([&] { return std::vector<Seen>(free_count); });
  // Column u (= row u, the matrix being symmetric) holds k(j, i) of every element around u at its
  // corner i, for its free corners j; the fixed ones go to the right-hand side. Gathered in
  // chunks of columns (fixed, whatever the threads), then copied into place.
  constexpr Index kChunk = 512;
  const Index chunks = (free_count + kChunk - 1) / kChunk;
  std::vector<std::vector<std::pair<int, double>>> gathered(chunks);
  std::vector<int> outer(free_count + 1, 0);
  rhs = Eigen::MatrixXd::Zero(free_count, values.cols());
  tbb::parallel_for(Index(0), chunks, [&](Index chunk) {
    std::vector<Seen>& seen = scratch.local();
    std::vector<std::pair<int, double>>& entries = gathered[chunk];
    for (Index u = chunk * kChunk, last = std::min(free_count, u + kChunk); u < last; ++u) {
      const std::size_t start = entries.size();
      for (Index k = first[u]; k < first[u + 1]; ++k) {
        const Index e = around[k] / corners;
        const int i = static_cast<int>(around[k] % corners);
        const double* k_e = &locals[e * block];
        const int* rows = &free_corner[e * corners];
        for (int j = 0; j < corners; ++j) {
          const int row = rows[j];
          if (row < 0) {
            rhs.row(u) -= k_e[i * corners + j] * values.row(elements(e, j));
          } else if (seen[row].column != u) {
            seen[row] = {static_cast<int>(u), static_cast<int>(entries.size())};
            entries.emplace_back(row, k_e[j * corners + i]);
          } else {
            entries[seen[row].slot].second += k_e[j * corners + i];
          }
        }
      }
      std::sort(entries.begin() + start, entries.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
      outer[u + 1] = static_cast<int>(entries.size() - start);
    }
  });
  for (Index u = 0; u < free_count; ++u) outer[u + 1] += outer[u];
  matrix.resize(free_count, free_count);
  matrix.resizeNonZeros(outer[free_count]);
  std::copy(outer.begin(), outer.end(), matrix.outerIndexPtr());
  int* inner = matrix.innerIndexPtr();
  double* value = matrix.valuePtr();
  tbb::parallel_for(Index(0), chunks, [&](Index chunk) {
    Index at = outer[chunk * kChunk];
    for (const auto& [row, sum] : gathered[chunk]) {
      inner[at] = row;
      value[at++] = sum;
    }
  });
}

}  // namespace morphomap::detail
