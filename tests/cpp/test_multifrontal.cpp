// The multifrontal Cholesky along a nested dissection against Eigen's simplicial LDL^T and the
// residual, on grid Laplacians in 2D and 3D with random weights, split grids (empty separators),
// a single leaf and an indefinite matrix.
#include "check.hpp"
#include "diffusion/multifrontal.hpp"
#include "diffusion/nested_dissection.hpp"

#include <Eigen/SparseCholesky>

#include <random>
#include <vector>

using morphomap::Index;
using morphomap::detail::MultifrontalCholesky;
using morphomap::detail::nested_dissection;

namespace {

struct Problem {
  Eigen::SparseMatrix<double> matrix;  // both triangles
  Eigen::MatrixXd positions;
};

// A weighted graph Laplacian of an nx x ny x nz grid of jittered points, plus `shift` on the
// diagonal; with `gap`, the edges across x = nx / 2 are left out (two separate blocks).
Problem grid(Index nx, Index ny, Index nz, double shift, bool gap, unsigned seed) {
  std::mt19937 random(seed);
  std::uniform_real_distribution<double> weight(0.5, 2.0), jitter(-0.3, 0.3);
  const auto id = [&](Index i, Index j, Index k) { return (k * ny + j) * nx + i; };
  const Index n = nx * ny * nz;
  Problem p{Eigen::SparseMatrix<double>(n, n), Eigen::MatrixXd(n, nz > 1 ? 3 : 2)};
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
        p.positions(v, 0) = i + jitter(random);
        p.positions(v, 1) = j + jitter(random);
        if (nz > 1) p.positions(v, 2) = k + jitter(random);
        if (i + 1 < nx && !(gap && i + 1 == nx / 2)) couple(v, id(i + 1, j, k));
        if (j + 1 < ny) couple(v, id(i, j + 1, k));
        if (k + 1 < nz) couple(v, id(i, j, k + 1));
        if (i + 1 < nx && j + 1 < ny && !(gap && i + 1 == nx / 2)) couple(v, id(i + 1, j + 1, k));  // triangles
      }
    }
  }
  p.matrix.setFromTriplets(entries.begin(), entries.end());
  return p;
}

// Solves with the multifrontal factorisation; nullopt-like empty matrix when it reports failure.
bool solve(const Problem& p, const Eigen::MatrixXd& rhs, Eigen::MatrixXd& x) {
  const auto dissection = nested_dissection(p.matrix, p.positions);
  const auto& order = dissection.permutation;
  Eigen::SparseMatrix<double> ordered(p.matrix.rows(), p.matrix.cols());
  ordered.selfadjointView<Eigen::Lower>() = p.matrix.selfadjointView<Eigen::Lower>().twistedBy(order);
  const MultifrontalCholesky cholesky(ordered, dissection.fronts);
  if (!cholesky.ok()) return false;
  x = order.transpose() * cholesky.solve(order * rhs);
  return true;
}

void check_against_simplicial(const Problem& p, unsigned seed) {
  std::mt19937 random(seed);
  std::normal_distribution<double> normal;
  Eigen::MatrixXd rhs(p.matrix.rows(), 3);
  for (Index i = 0; i < rhs.size(); ++i) rhs.data()[i] = normal(random);
  Eigen::MatrixXd x;
  CHECK(solve(p, rhs, x));
  if (x.rows() != rhs.rows()) return;
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> reference(p.matrix);
  const Eigen::MatrixXd expected = reference.solve(rhs);
  CHECK((x - expected).norm() <= 1e-10 * expected.norm());
  CHECK((p.matrix * x - rhs).norm() <= 1e-11 * rhs.norm());
}

}  // namespace

int main() {
  check_against_simplicial(grid(90, 70, 1, 1e-3, false, 1), 11);   // 2D, many levels
  check_against_simplicial(grid(16, 13, 11, 1e-3, false, 2), 12);  // 3D
  check_against_simplicial(grid(60, 40, 1, 1e-3, true, 3), 13);    // two blocks: an empty separator
  check_against_simplicial(grid(7, 5, 1, 1e-3, false, 4), 14);     // one leaf
  check_against_simplicial(grid(3000, 1, 1, 1e-3, false, 5), 15);  // a path: one-node separators
  // An indefinite matrix (a negative shift below the smallest eigenvalue) has no Cholesky factor.
  Eigen::MatrixXd x;
  CHECK(!solve(grid(40, 30, 1, -1.0, false, 6), Eigen::MatrixXd::Ones(1200, 1), x));
  return morphomap_test::failures() == 0 ? 0 : 1;
}
