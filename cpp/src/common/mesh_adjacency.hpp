#pragma once
// Who is next to whom in a mesh whose elements (triangles or tetrahedra) are rows of vertex
// indices, as compressed rows: the entries of vertex v are entries[first[v]] to
// entries[first[v + 1] - 1], in increasing order.
#include <morphomap/types.hpp>

#include <tbb/parallel_for.h>

#include <algorithm>
#include <vector>

namespace morphomap::detail {

struct CompressedRows {
  std::vector<Index> first, entries;
};

// The elements that have each vertex as a corner.
template <class Elements>
CompressedRows incident_elements(Index vertex_count, const Elements& elements) {
  CompressedRows rows;
  rows.first.assign(vertex_count + 1, 0);
  for (Index e = 0; e < elements.rows(); ++e) {
    for (Index i = 0; i < elements.cols(); ++i) ++rows.first[elements(e, i) + 1];
  }
  for (Index v = 0; v < vertex_count; ++v) rows.first[v + 1] += rows.first[v];
  rows.entries.resize(rows.first[vertex_count]);
  std::vector<Index> next(rows.first.begin(), rows.first.end() - 1);
  for (Index e = 0; e < elements.rows(); ++e) {
    for (Index i = 0; i < elements.cols(); ++i) rows.entries[next[elements(e, i)]++] = e;
  }
  return rows;
}

// The vertices that share an element with each vertex: gathered from each vertex's elements, on
// all cores.
template <class Elements>
CompressedRows neighbouring_vertices(Index vertex_count, const Elements& elements) {
  const CompressedRows around = incident_elements(vertex_count, elements);
  std::vector<std::vector<Index>> lists(vertex_count);
  tbb::parallel_for(Index(0), vertex_count, [&](Index v) {
    std::vector<Index>& list = lists[v];
    for (Index k = around.first[v]; k < around.first[v + 1]; ++k) {
      for (Index i = 0; i < elements.cols(); ++i) {
        const Index w = elements(around.entries[k], i);
        if (w != v) list.push_back(w);
      }
    }
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
  });
  CompressedRows rows;
  rows.first.reserve(vertex_count + 1);
  rows.first.push_back(0);
  for (const std::vector<Index>& list : lists) {
    rows.entries.insert(rows.entries.end(), list.begin(), list.end());
    rows.first.push_back(static_cast<Index>(rows.entries.size()));
  }
  return rows;
}

}  // namespace morphomap::detail
