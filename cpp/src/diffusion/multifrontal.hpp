#pragma once
// A sparse Cholesky factorisation A = L L^T that works in dense blocks: multifrontal, along the
// tree of a nested dissection (nested_dissection.hpp). Each front eliminates its separator (or
// leaf) in a dense matrix that holds its columns of A and the updates its children pass up; what
// is left of the front (the Schur complement on the ancestors' unknowns it touches) goes up to its
// parent. Eigen's SimplicialLDLT does the same arithmetic one sparse column at a time; the dense
// blocks run at the speed of Eigen's matrix products, and the two halves of every separator are
// factorised on cores of their own (TBB).
#include <morphomap/types.hpp>

#include "common/interrupt_check.hpp"
#include "diffusion/nested_dissection.hpp"

#include <tbb/parallel_for.h>
#include <Eigen/Cholesky>
#include <Eigen/Core>
#include <Eigen/SparseCore>

#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <vector>

namespace morphomap::detail {

class MultifrontalCholesky {
 public:
  // lower: symmetric positive definite, numbered as the dissection's fronts are (the permutation
  // already applied), its lower triangle stored (column-major; the upper one is not read).
  MultifrontalCholesky(const Eigen::SparseMatrix<double>& lower, const std::vector<DissectionFront>& fronts)
      : lower_(lower), fronts_(fronts), factors_(fronts.size()), updates_(fronts.size()) {
    if (!fronts_.empty()) factor_subtree(static_cast<int>(fronts_.size()) - 1);
    updates_.clear();
  }

  // False when a pivot was not positive (A not positive definite: singular, to rounding).
  bool ok() const { return !failed_.load(); }

  // A^{-1} rhs, every column (in the dissection's numbering).
  Eigen::MatrixXd solve(Eigen::MatrixXd x) const {
    Eigen::MatrixXd border;
    for (std::size_t t = 0; t < fronts_.size(); ++t) {  // L y = rhs, children first
      const Factor& f = factors_[t];
      auto pivots = x.middleRows(fronts_[t].pivot_begin, f.diagonal.rows());
      f.diagonal.triangularView<Eigen::Lower>().solveInPlace(pivots);
      if (f.border.empty()) continue;
      border.noalias() = f.below * pivots;
      for (std::size_t a = 0; a < f.border.size(); ++a) x.row(f.border[a]) -= border.row(a);
    }
    for (std::size_t t = fronts_.size(); t-- > 0;) {  // L^T x = y, parents first
      const Factor& f = factors_[t];
      auto pivots = x.middleRows(fronts_[t].pivot_begin, f.diagonal.rows());
      if (!f.border.empty()) {
        border.resize(f.border.size(), x.cols());
        for (std::size_t a = 0; a < f.border.size(); ++a) border.row(a) = x.row(f.border[a]);
        pivots.noalias() -= f.below.transpose() * border;
      }
      f.diagonal.triangularView<Eigen::Lower>().transpose().solveInPlace(pivots);
    }
    return x;
  }

 private:
  struct Factor {
    std::vector<Index> border;  // the ancestors' unknowns this subtree is coupled to, ascending
    Eigen::MatrixXd diagonal;   // L on the pivots (lower triangle)
    Eigen::MatrixXd below;      // L on the border rows and the pivot columns
  };

  void factor_subtree(int t) {
    const std::vector<int>& children = fronts_[t].children;
    // Tiny subtrees are not worth a task.
    if (fronts_[t].pivot_end - fronts_[t].begin > 4096) {
      tbb::parallel_for(std::size_t(0), children.size(), [&](std::size_t c) { factor_subtree(children[c]); });
    } else {
      for (const int child : children) factor_subtree(child);
    }
    factor_front(t);
  }

  void factor_front(int t) {
    check_interrupt();
    const DissectionFront& front = fronts_[t];
    const Index first = front.pivot_begin, end = front.pivot_end, k = end - first;
    Factor& f = factors_[t];
    // The border: unknowns after the subtree that a pivot column or a child's border reaches.
    for (Index j = first; j < end; ++j) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(lower_, j); it; ++it) {
        if (it.index() >= end) f.border.push_back(it.index());
      }
    }
    for (const int child : front.children) {
      for (const Index v : factors_[child].border) {
        // A dissection keeps a subtree's couplings inside it or on its ancestors' separators.
        if (v < first) throw std::logic_error("multifrontal: a child's border lies outside its parent");
        if (v >= end) f.border.push_back(v);
      }
    }
    std::sort(f.border.begin(), f.border.end());
    f.border.erase(std::unique(f.border.begin(), f.border.end()), f.border.end());
    const Index m = k + static_cast<Index>(f.border.size());
    const auto position = [&](Index v) {
      return v < end ? v - first
                     : k + static_cast<Index>(std::lower_bound(f.border.begin(), f.border.end(), v) - f.border.begin());
    };
    // The frontal matrix (lower triangle): A's pivot columns, then the children's updates.
    Eigen::MatrixXd front_matrix = Eigen::MatrixXd::Zero(m, m);
    for (Index j = first; j < end; ++j) {
      for (Eigen::SparseMatrix<double>::InnerIterator it(lower_, j); it; ++it) {
        if (it.index() >= j) front_matrix(position(it.index()), j - first) += it.value();
      }
    }
    std::vector<Index> at;
    for (const int child : front.children) {
      const std::vector<Index>& border = factors_[child].border;
      Eigen::MatrixXd& update = updates_[child];
      at.resize(border.size());
      for (std::size_t a = 0; a < border.size(); ++a) at[a] = position(border[a]);
      // Both borders ascend, so the child's lower triangle lands in the front's.
      for (std::size_t b = 0; b < border.size(); ++b) {
        for (std::size_t a = b; a < border.size(); ++a) front_matrix(at[a], at[b]) += update(a, b);
      }
      update = Eigen::MatrixXd();
    }
    if (k > 0) {
      Eigen::Ref<Eigen::MatrixXd> diagonal = front_matrix.topLeftCorner(k, k);
      Eigen::LLT<Eigen::Ref<Eigen::MatrixXd>> llt(diagonal);
      if (llt.info() != Eigen::Success) failed_.store(true);
      auto below = front_matrix.bottomLeftCorner(m - k, k);
      diagonal.triangularView<Eigen::Lower>().transpose().solveInPlace<Eigen::OnTheRight>(below);
      front_matrix.bottomRightCorner(m - k, m - k).selfadjointView<Eigen::Lower>().rankUpdate(below, -1.0);
    }
    f.diagonal = front_matrix.topLeftCorner(k, k);
    f.below = front_matrix.bottomLeftCorner(m - k, k);
    updates_[t] = front_matrix.bottomRightCorner(m - k, m - k);
  }

  const Eigen::SparseMatrix<double>& lower_;
  const std::vector<DissectionFront>& fronts_;
  std::vector<Factor> factors_;
  std::vector<Eigen::MatrixXd> updates_;  // each front's Schur complement on its border, until its parent takes it
  std::atomic<bool> failed_{false};
};

}  // namespace morphomap::detail
