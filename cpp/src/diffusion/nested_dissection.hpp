#pragma once
// A fill-reducing order for the sparse Cholesky factorisation of a mesh's stiffness matrix, from
// the positions of its unknowns: geometric nested dissection. Eigen's simplicial factorisation
// with its minimum-degree order (AMD) fills in more on large 2D meshes; numbering each half of the
// mesh before the nodes that separate them keeps the two halves' factors apart. The dissection's
// tree (each separator a front above the fronts of its two halves) is what the multifrontal
// factorisation (multifrontal.hpp) works along.
#include <morphomap/types.hpp>

#include <Eigen/SparseCore>

#include <algorithm>
#include <vector>

namespace morphomap::detail {

// A node of the dissection tree, in the new numbering: the unknowns it eliminates (a separator,
// or all of a small leaf) are pivot_begin..pivot_end, after those of its subtree from `begin`.
struct DissectionFront {
  Index begin = 0, pivot_begin = 0, pivot_end = 0;
  std::vector<int> children;
};

// The permutation p with p(i) the new index of unknown i, and the fronts in post-order (children
// before their parent; the root last).
struct Dissection {
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> permutation;
  std::vector<DissectionFront> fronts;
};

namespace nested_dissection_detail {

// Orders `nodes` (their positions, and the matrix's pattern as the graph) into `order`.
class Dissector {
 public:
  Dissector(const Eigen::SparseMatrix<double>& matrix, const Eigen::MatrixXd& positions,
            std::vector<DissectionFront>& fronts)
      : matrix_(matrix), positions_(positions), part_(matrix.rows(), -1), fronts_(fronts) {}

  // Appends the new order of `nodes` to `out`; returns their front (-1: no nodes).
  int order(std::vector<Index>& nodes, std::vector<Index>& out) {
    // Below this, the order within hardly matters and a dense front is cheaper than splitting.
    constexpr std::size_t kLeaf = 64;
    const Index begin = static_cast<Index>(out.size());
    if (nodes.empty()) return -1;
    if (nodes.size() <= kLeaf) {
      out.insert(out.end(), nodes.begin(), nodes.end());
      return add_front(begin, begin, static_cast<Index>(out.size()), {});
    }
    // Split at the median of the widest coordinate.
    int axis = 0;
    double widest = -1.0;
    for (int a = 0; a < positions_.cols(); ++a) {
      double lo = positions_(nodes[0], a), hi = lo;
      for (const Index v : nodes) {
        lo = std::min(lo, positions_(v, a));
        hi = std::max(hi, positions_(v, a));
      }
      if (hi - lo > widest) {
        widest = hi - lo;
        axis = a;
      }
    }
    const auto middle = nodes.begin() + static_cast<std::ptrdiff_t>(nodes.size() / 2);
    std::nth_element(nodes.begin(), middle, nodes.end(),
                     [&](Index a, Index b) { return positions_(a, axis) < positions_(b, axis); });
    const int first = next_part_++, second = next_part_++;
    for (auto v = nodes.begin(); v != nodes.end(); ++v) part_[*v] = v < middle ? first : second;
    // The separator: nodes of the first half coupled to the second.
    std::vector<Index> left, right(middle, nodes.end()), separator;
    for (auto v = nodes.begin(); v != middle; ++v) {
      bool coupled = false;
      for (Eigen::SparseMatrix<double>::InnerIterator it(matrix_, *v); it && !coupled; ++it) {
        coupled = part_[it.index()] == second;
      }
      (coupled ? separator : left).push_back(*v);
    }
    nodes.clear();
    nodes.shrink_to_fit();
    std::vector<int> children;
    for (std::vector<Index>* half : {&left, &right}) {
      const int child = order(*half, out);
      if (child >= 0) children.push_back(child);
    }
    const Index pivot_begin = static_cast<Index>(out.size());
    out.insert(out.end(), separator.begin(), separator.end());
    return add_front(begin, pivot_begin, static_cast<Index>(out.size()), std::move(children));
  }

 private:
  int add_front(Index begin, Index pivot_begin, Index pivot_end, std::vector<int> children) {
    DissectionFront front;
    front.begin = begin;
    front.pivot_begin = pivot_begin;
    front.pivot_end = pivot_end;
    front.children = std::move(children);
    fronts_.push_back(std::move(front));
    return static_cast<int>(fronts_.size()) - 1;
  }

  const Eigen::SparseMatrix<double>& matrix_;
  const Eigen::MatrixXd& positions_;
  std::vector<int> part_;  // the half a node was last put into (ids unique per split)
  int next_part_ = 0;
  std::vector<DissectionFront>& fronts_;
};

}  // namespace nested_dissection_detail

// The dissection of the unknowns. matrix: symmetric, both triangles stored (column-major);
// positions: one row per unknown.
inline Dissection nested_dissection(const Eigen::SparseMatrix<double>& matrix, const Eigen::MatrixXd& positions) {
  std::vector<Index> nodes(matrix.rows()), order;
  for (Index v = 0; v < matrix.rows(); ++v) nodes[v] = v;
  order.reserve(nodes.size());
  Dissection out;
  nested_dissection_detail::Dissector(matrix, positions, out.fronts).order(nodes, order);
  out.permutation.resize(matrix.rows());
  for (std::size_t k = 0; k < order.size(); ++k) out.permutation.indices()[order[k]] = static_cast<int>(k);
  return out;
}

}  // namespace morphomap::detail
