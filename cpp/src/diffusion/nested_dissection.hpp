#pragma once
// A fill-reducing order for the sparse Cholesky factorisation of a mesh's stiffness matrix, from
// the positions of its unknowns: geometric nested dissection. Eigen's simplicial factorisation
// with its minimum-degree order (AMD) fills in more on large 2D meshes; numbering each half of the
// mesh before the nodes that separate them keeps the two halves' factors apart.
#include <morphomap/types.hpp>

#include <Eigen/SparseCore>

#include <algorithm>
#include <vector>

namespace morphomap::detail {

namespace nested_dissection_detail {

// Orders `nodes` (their positions, and the matrix's pattern as the graph) into `order`.
class Dissection {
 public:
  Dissection(const Eigen::SparseMatrix<double>& matrix, const Eigen::MatrixXd& positions)
      : matrix_(matrix), positions_(positions), part_(matrix.rows(), -1) {}

  void order(std::vector<Index>& nodes, std::vector<Index>& out) {
    constexpr std::size_t kLeaf = 64;  // below this, the order within hardly matters
    if (nodes.size() <= kLeaf) {
      out.insert(out.end(), nodes.begin(), nodes.end());
      return;
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
    order(left, out);
    order(right, out);
    out.insert(out.end(), separator.begin(), separator.end());
  }

 private:
  const Eigen::SparseMatrix<double>& matrix_;
  const Eigen::MatrixXd& positions_;
  std::vector<int> part_;  // the half a node was last put into (ids unique per split)
  int next_part_ = 0;
};

}  // namespace nested_dissection_detail

// The permutation p with p(i) the new index of unknown i. matrix: symmetric, both triangles
// stored (column-major); positions: one row per unknown.
inline Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> nested_dissection(
    const Eigen::SparseMatrix<double>& matrix, const Eigen::MatrixXd& positions) {
  std::vector<Index> nodes(matrix.rows()), order;
  for (Index v = 0; v < matrix.rows(); ++v) nodes[v] = v;
  order.reserve(nodes.size());
  nested_dissection_detail::Dissection(matrix, positions).order(nodes, order);
  Eigen::PermutationMatrix<Eigen::Dynamic, Eigen::Dynamic, int> p(matrix.rows());
  for (std::size_t k = 0; k < order.size(); ++k) p.indices()[order[k]] = static_cast<int>(k);
  return p;
}

}  // namespace morphomap::detail
