#pragma once
// P1 finite elements for Dirichlet problems of the Laplace equation on triangles (2D) and
// tetrahedra (3D): diffusion mapping's potential and the harmonic extension of a boundary field.
#include <morphomap/errors.hpp>
#include <morphomap/interrupt.hpp>
#include <morphomap/types.hpp>

#include "common/interrupt_check.hpp"
#include "diffusion/block_cg.hpp"
#include "diffusion/free_assembly.hpp"
#include "diffusion/multifrontal.hpp"
#include "diffusion/nested_dissection.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/LU>
#include <Eigen/OrderingMethods>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <exception>
#include <memory>
#include <thread>
#include <vector>

namespace morphomap::detail {

// crossing_vertex: on both surfaces, where they cross; c = 0 there.
enum Kind : char { free_vertex = 0, source_vertex = 1, target_vertex = 2, crossing_vertex = 3 };

// The P1 stiffness matrix of a triangle: grad phi_i . grad phi_j * area (orientation-free).
inline Eigen::Matrix3d triangle_stiffness(const Vec2 (&p)[3]) {
  const Vec2 a = p[1] - p[0], b = p[2] - p[0];
  const double area2 = std::abs(a.x() * b.y() - a.y() * b.x());
  Eigen::Matrix3d k;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      k(i, j) = (p[(i + 2) % 3] - p[(i + 1) % 3]).dot(p[(j + 2) % 3] - p[(j + 1) % 3]) / (2.0 * area2);
    }
  }
  return k;
}

// Gradients of the barycentric coordinates of tetrahedron t (rows) and its signed volume.
template <class Vertices, class Tets>
double tetrahedron_gradients(const Vertices& vertices, const Tets& tets, Index t, Eigen::Matrix<double, 4, 3>& g) {
  const Eigen::Vector3d p0 = vertices.row(tets(t, 0)).transpose();
  Eigen::Matrix3d edges;
  for (int i = 0; i < 3; ++i) edges.col(i) = vertices.row(tets(t, i + 1)).transpose() - p0;
  const double det = edges.determinant();
  const Eigen::Matrix3d inverse = edges.inverse();
  g.bottomRows(3) = inverse;
  g.row(0) = -inverse.colwise().sum();
  return det / 6.0;
}

// The sparse LDL^T solve (one factorisation, every column of rhs), on a thread of its own so
// that an interrupt is seen while it runs (a factorisation cannot stop half way): on an interrupt
// the caller returns at once and the thread finishes on its own, its matrices freed with it.
// Ordering: Eigen's fill-reducing order (NaturalOrdering when the caller has ordered the rows).
template <class Ordering = Eigen::AMDOrdering<int>>
Eigen::MatrixXd solve_direct(Eigen::SparseMatrix<double> stiffness, const Eigen::MatrixXd& rhs) {
  struct Work {
    Eigen::SparseMatrix<double> matrix;
    Eigen::MatrixXd rhs, x;
    bool singular = false;
    std::exception_ptr failure;
    std::atomic<bool> done{false};
  };
  auto work = std::make_shared<Work>();
  work->matrix = std::move(stiffness);
  work->rhs = rhs;
  std::thread worker([work] {
    try {
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>, Eigen::Lower, Ordering> direct(work->matrix);
      if (direct.info() != Eigen::Success)
        work->singular = true;
      else
        work->x = direct.solve(work->rhs);
    } catch (...) {
      work->failure = std::current_exception();
    }
    work->done.store(true);
  });
  while (!work->done.load()) {
    if (interrupt_requested()) {
      worker.detach();
      throw Interrupted();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  worker.join();
  if (work->failure) std::rethrow_exception(work->failure);
  if (work->singular) {
    throw GeometryError("the Laplace system is singular: a part of the region touches neither boundary");
  }
  return std::move(work->x);
}

// The discrete harmonic function of each column of `values`: at the vertices where `fixed` is
// set, the given values; at the others, the P1 solution of the Laplace equation. elements:
// (E, K) vertex indices; local(e) returns element e's K x K stiffness matrix. With iterative,
// conjugate gradients with an incomplete Cholesky preconditioner come first, every column at
// once (block_cg.hpp; less memory and time for 3D meshes), to the relative residual
// `tolerance`, the sparse LDL^T factorisation otherwise or as the fallback. With `positions` (a row per vertex), the
// factorisation is the multifrontal Cholesky along a nested dissection of them (multifrontal.hpp; dense blocks, all
// cores) rather than Eigen's simplicial LDL^T in its AMD order.
template <class Elements, class Local>
Eigen::MatrixXd solve_dirichlet_values(Index vertex_count, const Elements& elements, const std::vector<char>& fixed,
                                       Eigen::MatrixXd values, Local local, bool iterative, double tolerance = 1e-10,
                                       const Eigen::MatrixXd& positions = {}) {
  std::vector<Index> unknown(vertex_count, -1);
  Index free_count = 0;
  for (Index v = 0; v < vertex_count; ++v) {
    if (!fixed[v]) unknown[v] = free_count++;
  }
  if (free_count == 0) return values;
  Eigen::SparseMatrix<double> stiffness;
  Eigen::MatrixXd rhs;
  assemble_free(elements, local, unknown, free_count, values, stiffness, rhs);
  Eigen::MatrixXd x(free_count, values.cols());
  bool solved = false;
  if (iterative) {
    solved = solve_block_cg(stiffness, rhs, tolerance, std::max<Index>(1000, free_count), x);
  }
  if (!solved && positions.rows() == vertex_count) {
    Eigen::MatrixXd free_positions(free_count, positions.cols());
    for (Index v = 0; v < vertex_count; ++v) {
      if (unknown[v] >= 0) free_positions.row(unknown[v]) = positions.row(v);
    }
    const Dissection dissection = nested_dissection(stiffness, free_positions);
    const auto& order = dissection.permutation;
    // The lower triangle is all the factorisation reads.
    Eigen::SparseMatrix<double> ordered(free_count, free_count);
    ordered.selfadjointView<Eigen::Lower>() = stiffness.selfadjointView<Eigen::Lower>().twistedBy(order);
    const MultifrontalCholesky cholesky(ordered, dissection.fronts);
    if (!cholesky.ok()) {
      throw GeometryError("the Laplace system is singular: a part of the region touches neither boundary");
    }
    x = order.transpose() * cholesky.solve(order * rhs);
  } else if (!solved) {
    x = solve_direct(std::move(stiffness), rhs);
  }
  for (Index v = 0; v < vertex_count; ++v) {
    if (unknown[v] >= 0) values.row(v) = x.row(unknown[v]);
  }
  return values;
}

// Diffusion mapping's potential: c = 1 on the source vertices, 0 on the target (and crossing)
// vertices, harmonic elsewhere.
template <class Elements, class Local>
Vector solve_dirichlet(Index vertex_count, const Elements& elements, const std::vector<char>& kind, Local local,
                       bool iterative) {
  std::vector<char> fixed(vertex_count);
  Eigen::MatrixXd c = Eigen::MatrixXd::Zero(vertex_count, 1);
  for (Index v = 0; v < vertex_count; ++v) {
    fixed[v] = kind[v] != free_vertex;
    c(v, 0) = kind[v] == source_vertex ? 1.0 : 0.0;
  }
  return solve_dirichlet_values(vertex_count, elements, fixed, std::move(c), local, iterative).col(0);
}

}  // namespace morphomap::detail
