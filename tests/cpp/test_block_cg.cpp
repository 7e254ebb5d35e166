// Conjugate gradients on a block of right-hand sides against Eigen's simplicial LDL^T and the
// residual, on 3D grid Laplacians with random weights: three columns together, one, four (a
// group of three and one), a zero column beside others, the same answer bit for bit on one
// thread and on two, and an iteration budget too small reported as a failure.
#include "check.hpp"
#include "diffusion/block_cg.hpp"

#include <Eigen/SparseCholesky>

#include <tbb/global_control.h>

#include <cstring>
#include <random>
#include <vector>

using morphomap::Index;
using morphomap::detail::solve_block_cg;

namespace {

// A weighted graph Laplacian of an nx x ny x nz grid plus `shift` on the diagonal (both triangles).
Eigen::SparseMatrix<double> grid(Index nx, Index ny, Index nz, double shift, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> weight(0.5, 2.0);
  const auto id = [&](Index i, Index j, Index k) { return (k * ny + j) * nx + i; };
  const Index n = nx * ny * nz;
  std::vector<Eigen::Triplet<double>> entries;
  const auto couple = [&](Index a, Index b) {
    const double w = weight(random);
    entries.emplace_back(a, a, w);
    entries.emplace_back(b, b, w);
    entries.emplace_back(a, b, -w);
    entries.emplace_back(b, a, -w);
  };
  for (Index k = 0; k < nz; ++k) {
    for (Index j = 0; j < ny; ++j) {
      for (Index i = 0; i < nx; ++i) {
        const Index v = id(i, j, k);
        entries.emplace_back(v, v, shift);
        if (i + 1 < nx) couple(v, id(i + 1, j, k));
        if (j + 1 < ny) couple(v, id(i, j + 1, k));
        if (k + 1 < nz) couple(v, id(i, j, k + 1));
        if (i + 1 < nx && j + 1 < ny) couple(v, id(i + 1, j + 1, k));
      }
    }
  }
  Eigen::SparseMatrix<double> matrix(n, n);
  matrix.setFromTriplets(entries.begin(), entries.end());
  return matrix;
}

Eigen::MatrixXd random_columns(Index rows, Index cols, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd rhs(rows, cols);
  for (Index i = 0; i < rhs.size(); ++i) rhs.data()[i] = normal(random);
  return rhs;
}

// Each column to the relative residual 1e-10 and to the direct solution within what that
// residual allows (the grids' condition numbers are below 1e3 with this shift).
void check_against_simplicial(const Eigen::SparseMatrix<double>& matrix, const Eigen::MatrixXd& rhs) {
  Eigen::MatrixXd x;
  CHECK(solve_block_cg(matrix, rhs, 1e-10, 1000, x));
  CHECK(x.rows() == rhs.rows() && x.cols() == rhs.cols());
  if (x.rows() != rhs.rows() || x.cols() != rhs.cols()) return;
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> reference(matrix);
  const Eigen::MatrixXd expected = reference.solve(rhs);
  for (Index c = 0; c < rhs.cols(); ++c) {
    const double scale = rhs.col(c).norm();
    CHECK((matrix * x.col(c) - rhs.col(c)).norm() <= 1e-10 * scale);
    CHECK((x.col(c) - expected.col(c)).norm() <= 1e-7 * std::max(expected.col(c).norm(), 1e-300));
    if (scale == 0) CHECK(x.col(c).isZero(0));
  }
}

}  // namespace

int main() {
  const Eigen::SparseMatrix<double> matrix = grid(24, 19, 17, 1e-2, 1);
  const Index n = matrix.rows();
  check_against_simplicial(matrix, random_columns(n, 3, 2));
  check_against_simplicial(matrix, random_columns(n, 1, 3));
  check_against_simplicial(matrix, random_columns(n, 4, 4));
  Eigen::MatrixXd with_zero = random_columns(n, 3, 5);
  with_zero.col(1).setZero();
  check_against_simplicial(matrix, with_zero);
  // Columns that differ in scale by 1e6 each reach their own relative residual.
  Eigen::MatrixXd scaled = random_columns(n, 2, 6);
  scaled.col(0) *= 1e6;
  check_against_simplicial(matrix, scaled);

  // The same bits whatever the number of threads.
  const Eigen::MatrixXd rhs = random_columns(n, 3, 7);
  Eigen::MatrixXd one, two;
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 1);
    CHECK(solve_block_cg(matrix, rhs, 1e-10, 1000, one));
  }
  {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, 2);
    CHECK(solve_block_cg(matrix, rhs, 1e-10, 1000, two));
  }
  CHECK(one.size() == two.size() && std::memcmp(one.data(), two.data(), one.size() * sizeof(double)) == 0);

  // Too few iterations: reported rather than answered.
  Eigen::MatrixXd x;
  CHECK(!solve_block_cg(matrix, rhs, 1e-10, 5, x));
  return morphomap_test::failures() == 0 ? 0 : 1;
}
