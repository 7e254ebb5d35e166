#pragma once
// P1 finite elements for the Dirichlet problem of diffusion mapping, shared by the 2D (triangle)
// and 3D (tetrahedron) solvers: c = 1 on the source, 0 on the target, harmonic elsewhere.
#include <morphomap/errors.hpp>
#include <morphomap/interrupt.hpp>
#include <morphomap/types.hpp>

#include "interrupt_check.hpp"

#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <exception>
#include <memory>
#include <thread>
#include <vector>

namespace morphomap::detail {

// crossing_vertex: on both surfaces, where they cross; c = 0 there.
enum Kind : char { free_vertex = 0, source_vertex = 1, target_vertex = 2, crossing_vertex = 3 };

// elements: (E, K) vertex indices; local(e) returns element e's K x K stiffness matrix. With
// iterative, conjugate gradients with an incomplete Cholesky preconditioner come first (less
// memory and time for 3D meshes), the sparse LDL^T factorisation otherwise or as the fallback.
constexpr Index kIterationsPerRound = 100;

// The sparse LDL^T solve, on a thread of its own so that an interrupt is seen while it runs (a
// factorisation cannot stop half way): on an interrupt the caller returns at once and the thread
// finishes on its own, its matrices freed with it.
inline Vector solve_direct(Eigen::SparseMatrix<double> stiffness, const Vector& rhs) {
  struct Work {
    Eigen::SparseMatrix<double> matrix;
    Vector rhs, x;
    bool singular = false;
    std::exception_ptr failure;
    std::atomic<bool> done{false};
  };
  auto work = std::make_shared<Work>();
  work->matrix = std::move(stiffness);
  work->rhs = rhs;
  std::thread worker([work] {
    try {
      Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> direct(work->matrix);
      if (direct.info() != Eigen::Success) work->singular = true;
      else work->x = direct.solve(work->rhs);
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

template <class Elements, class Local>
Vector solve_dirichlet(Index vertex_count, const Elements& elements, const std::vector<char>& kind,
                       Local local, bool iterative) {
  std::vector<Index> unknown(vertex_count, -1);
  Index free_count = 0;
  Vector c(vertex_count);
  for (Index v = 0; v < vertex_count; ++v) {
    if (kind[v] == free_vertex) unknown[v] = free_count++;
    c[v] = kind[v] == source_vertex ? 1.0 : 0.0;
  }
  if (free_count == 0) return c;
  const int corners = static_cast<int>(elements.cols());
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(corners * corners * elements.rows());
  Vector rhs = Vector::Zero(free_count);
  for (Index e = 0; e < elements.rows(); ++e) {
    const auto k = local(e);
    for (int i = 0; i < corners; ++i) {
      const Index vi = elements(e, i);
      if (unknown[vi] < 0) continue;
      for (int j = 0; j < corners; ++j) {
        const Index vj = elements(e, j);
        if (unknown[vj] >= 0) {
          entries.emplace_back(unknown[vi], unknown[vj], k(i, j));
        } else {
          rhs[unknown[vi]] -= k(i, j) * c[vj];
        }
      }
    }
  }
  Eigen::SparseMatrix<double> stiffness(free_count, free_count);
  stiffness.setFromTriplets(entries.begin(), entries.end());
  Vector x;
  bool solved = false;
  if (iterative) {
    Eigen::ConjugateGradient<Eigen::SparseMatrix<double>, Eigen::Lower | Eigen::Upper,
                             Eigen::IncompleteCholesky<double>>
        cg;
    cg.setTolerance(1e-10);
    cg.compute(stiffness);
    if (cg.info() == Eigen::Success) {
      // In rounds of iterations, each continuing from the last, so that an interrupt is seen.
      const Index budget = std::max<Index>(1000, free_count);
      x = Vector::Zero(free_count);
      cg.setMaxIterations(kIterationsPerRound);
      for (Index done = 0; done < budget; done += kIterationsPerRound) {
        check_interrupt();
        x = cg.solveWithGuess(rhs, x);
        if (cg.info() != Eigen::NoConvergence) break;
      }
    }
    solved = cg.info() == Eigen::Success && x.allFinite();
  }
  if (!solved) x = solve_direct(std::move(stiffness), rhs);
  for (Index v = 0; v < vertex_count; ++v) {
    if (unknown[v] >= 0) c[v] = x[unknown[v]];
  }
  return c;
}

}  // namespace morphomap::detail
