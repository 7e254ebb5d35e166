#pragma once
// Conjugate gradients for every column of a right-hand side at once, preconditioned by Eigen's
// incomplete Cholesky factor. The columns run in lockstep, each with its own step lengths, so
// that each iteration reads the matrix and the factor once for all of them (both passes are
// bound by memory, not arithmetic): the three components of a harmonic extension cost little
// more than one. The work happens in the factor's ordering and scaling, so that an iteration
// has no permutation in it.
//
// Bit-for-bit the same answer on any number of threads (diffusion mapping's potential must be):
// the product with the matrix is parallel by rows, each row summed in a fixed order; the dot
// products are summed over fixed chunks of rows whatever the threads, combined in chunk order;
// the triangular solves are serial.
#include <morphomap/types.hpp>

#include "common/interrupt_check.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCore>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <vector>

namespace morphomap::detail {

// Conjugate gradients on B y = c for K columns (rows of the blocks hold the K values of a row,
// K fixed at compile time so that the inner loops unroll), preconditioned by (L L^T)^-1, until
// each column's sum of weight * residual^2 is below tolerance^2 times its first. B: symmetric,
// both triangles; L: compressed columns, the diagonal first in each.
template <int K>
bool block_cg_columns(const Eigen::SparseMatrix<double>& b, const Eigen::SparseMatrix<double>& l,
                      const Eigen::VectorXd& weight, const Eigen::MatrixXd& c, double tolerance, Index max_iterations,
                      Eigen::MatrixXd& solution) {
  constexpr Index kChunk = 4096;  // rows per partial dot product: fixed, so the sums never depend on the threads
  const Index n = b.rows();
  using Row = Eigen::Array<double, K, 1>;
  std::vector<Row> y(n, Row::Zero()), r(n), z(n), p(n), q(n);
  for (Index i = 0; i < n; ++i) r[i] = c.row(i).transpose().array();

  const Index chunks = (n + kChunk - 1) / kChunk;
  std::vector<Row> partial(chunks);
  // Per-column dot products, over fixed chunks of rows combined in chunk order.
  const auto dots = [&](const std::vector<Row>& u, const std::vector<Row>& v) {
    tbb::parallel_for(Index(0), chunks, [&](Index chunk) {
      Row sum = Row::Zero();
      for (Index i = chunk * kChunk, end = std::min(n, (chunk + 1) * kChunk); i < end; ++i) sum += u[i] * v[i];
      partial[chunk] = sum;
    });
    Row total = Row::Zero();
    for (const Row& sum : partial) total += sum;
    return total;
  };
  const int* b_starts = b.outerIndexPtr();
  const int* b_rows = b.innerIndexPtr();
  const double* b_values = b.valuePtr();
  const auto multiply = [&](const std::vector<Row>& u, std::vector<Row>& out) {
    tbb::parallel_for(tbb::blocked_range<Index>(0, n, 1024), [&](const tbb::blocked_range<Index>& range) {
      for (Index i = range.begin(); i < range.end(); ++i) {
        Row sum = Row::Zero();
        for (int e = b_starts[i]; e < b_starts[i + 1]; ++e) sum += b_values[e] * u[b_rows[e]];
        out[i] = sum;
      }
    });
  };
  // z = (L L^T)^-1 r: forward along the columns of L, then back along the rows of L^T.
  const int* starts = l.outerIndexPtr();
  const int* rows = l.innerIndexPtr();
  const double* values = l.valuePtr();
  const auto precondition = [&](const std::vector<Row>& in, std::vector<Row>& out) {
    out = in;
    for (Index j = 0; j < n; ++j) {
      const Row v = out[j] / values[starts[j]];
      out[j] = v;
      for (int e = starts[j] + 1; e < starts[j + 1]; ++e) out[rows[e]] -= values[e] * v;
    }
    for (Index j = n - 1; j >= 0; --j) {
      Row v = out[j];
      for (int e = starts[j] + 1; e < starts[j + 1]; ++e) v -= values[e] * out[rows[e]];
      out[j] = v / values[starts[j]];
    }
  };

  // The residual of the caller's system, |S^-1 r|, not of B's: the tolerance is the caller's.
  const auto residual_norms = [&] {
    tbb::parallel_for(Index(0), chunks, [&](Index chunk) {
      Row sum = Row::Zero();
      for (Index i = chunk * kChunk, end = std::min(n, (chunk + 1) * kChunk); i < end; ++i) {
        sum += weight[i] * r[i] * r[i];
      }
      partial[chunk] = sum;
    });
    Row total = Row::Zero();
    for (const Row& sum : partial) total += sum;
    return total;
  };
  Row residual = residual_norms();
  const Row bound = (tolerance * tolerance) * residual;
  Row active;
  const auto update_active = [&] {
    active = (residual > bound && residual > 0.0).template cast<double>();
    return active.any();
  };
  bool running = update_active();
  precondition(r, z);
  p = z;
  Row rho = dots(r, z);
  for (Index iteration = 0; running; ++iteration) {
    if (iteration >= max_iterations) return false;
    check_interrupt();
    multiply(p, q);
    // A finished column keeps its answer: its step is 0.
    const Row alpha = (active > 0).select(rho / dots(p, q), Row::Zero());
    tbb::parallel_for(tbb::blocked_range<Index>(0, n, 4096), [&](const tbb::blocked_range<Index>& range) {
      for (Index i = range.begin(); i < range.end(); ++i) {
        y[i] += alpha * p[i];
        r[i] -= alpha * q[i];
      }
    });
    residual = residual_norms();
    if (!residual.allFinite()) return false;
    running = update_active();
    if (!running) break;
    precondition(r, z);
    const Row next = dots(r, z);
    const Row beta = (active > 0).select(next / rho, Row::Zero());
    rho = next;
    tbb::parallel_for(tbb::blocked_range<Index>(0, n, 4096), [&](const tbb::blocked_range<Index>& range) {
      for (Index i = range.begin(); i < range.end(); ++i) p[i] = z[i] + beta * p[i];
    });
  }
  solution.resize(n, K);
  for (Index i = 0; i < n; ++i) solution.row(i) = y[i].transpose().matrix();
  return solution.allFinite();
}

// The solution of A x = rhs for each column (A symmetric positive definite, both triangles
// stored), each to the relative residual |A x - b| <= tolerance |b|. Returns false (x
// unspecified) when the incomplete factorisation fails or a column does not converge within
// max_iterations.
inline bool solve_block_cg(const Eigen::SparseMatrix<double>& a, const Eigen::MatrixXd& rhs, double tolerance,
                           Index max_iterations, Eigen::MatrixXd& x) {
  const Index n = a.rows();
  x = Eigen::MatrixXd::Zero(n, rhs.cols());
  if (n == 0 || rhs.cols() == 0) return true;
  Eigen::IncompleteCholesky<double, Eigen::Lower, Eigen::AMDOrdering<int>> ic(a);
  if (ic.info() != Eigen::Success) return false;
  const Eigen::VectorXd& scale = ic.scalingS();
  const auto& order = ic.permutationP();
  // B = S P A P^T S, whose incomplete factor is L: B y = S P rhs, x = P^T S y.
  Eigen::SparseMatrix<double> b(n, n);
  b = a.selfadjointView<Eigen::Lower>().twistedBy(order);
  for (Index i = 0; i < n; ++i) {
    for (Eigen::SparseMatrix<double>::InnerIterator it(b, i); it; ++it) it.valueRef() *= scale[i] * scale[it.index()];
  }
  const Eigen::MatrixXd c = scale.asDiagonal() * (order * rhs);
  const Eigen::VectorXd weight = scale.cwiseAbs2().cwiseInverse();
  Eigen::MatrixXd y(n, rhs.cols());
  // Up to three columns at a time (the components of a 3D field).
  for (Index first = 0; first < rhs.cols(); first += 3) {
    const Index count = std::min<Index>(3, rhs.cols() - first);
    Eigen::MatrixXd part;
    const Eigen::MatrixXd columns = c.middleCols(first, count);
    const bool ok = count == 3 ? block_cg_columns<3>(b, ic.matrixL(), weight, columns, tolerance, max_iterations, part)
                    : count == 2
                        ? block_cg_columns<2>(b, ic.matrixL(), weight, columns, tolerance, max_iterations, part)
                        : block_cg_columns<1>(b, ic.matrixL(), weight, columns, tolerance, max_iterations, part);
    if (!ok) return false;
    y.middleCols(first, count) = part;
  }
  x = order.inverse() * (scale.asDiagonal() * y);
  return true;
}

}  // namespace morphomap::detail
