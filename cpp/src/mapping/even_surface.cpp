// The energy and its steps. With r_j = A'_j / (alpha A_j) the area ratio of triangle j against
// the surfaces' own, E = sum_j (r_j - 1)^2 is zero exactly where every triangle's image keeps its
// share of S2's area (the radial map between concentric spheres, any similarity), and it is QM1
// of the 3D quality measure, so lowering it is what makes the field even. Its gradient at end q_i
// of triangle j is 2 (r_j - 1) / (alpha A_j) * dA'_j/dq_i, with dA'/dq_i = n' x (q_l - q_k) / 2 (n'
// the image's unit normal, (i, k, l) in order round it).
//
// A step moves every end at once, each within S2's tangent plane at it (two coordinates per end),
// by the Levenberg-Marquardt step of the residuals r_j - 1: (J^T J + lambda (L + eps I)) x =
// -J^T (r - 1), with L the graph Laplacian of S1's edges. E alone says nothing about a triangle's
// shape (a shear keeps its area), so J^T J is singular; the Laplacian damping makes the step the
// smoothest one that evens the areas (a Sobolev gradient step for large lambda), and lambda falls
// while steps succeed and rises while the step has to shrink. The ends then go onto S2 by closest
// point. A flip-preventing line search, as locally injective parameterisation methods use: each
// end's share of the step is first lowered until no triangle passes through zero area on the
// straight way (limit_shares); an end at a corner of a triangle that the projected step still
// folds stays where it is for that step (so one tight spot does not hold every end back), and
// every share is halved while the energy does not fall. "optimal" starts from auto's field,
// complete and fold-free, and every step keeps it so. A triangle folded at the start (auto's last
// resort, untangling) counts its ratio negative and kFoldWeight times, so the step turns it back
// first; no step folds a triangle that was not folded. Each end moving by its own Gauss-Newton step
// instead stalled where the fold constraint binds (lung-like pair QM 0.89 against 0.001 now;
// bench/README, "Even 3D maps").
#include "mapping/even_surface.hpp"

#include "common/interrupt_check.hpp"
#include "quality/folds.hpp"
#include "surfaces/surface_util.hpp"

#include <Eigen/Geometry>
#include <Eigen/SparseCholesky>
#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace morphomap::detail {
namespace {

using Tangents = Eigen::Matrix<double, 3, 2>;

// A folded triangle's term weighs this much more: turning it back comes before evening the rest.
constexpr double kFoldWeight = 100.0;

// Iterations over which the energy must fall by options.tolerance of itself to go on.
constexpr std::size_t kWindow = 10;

double twice_area(const V3& a, const V3& b, const V3& c) { return (b - a).cross(c - a).norm(); }

// A folded triangle's ratio counts negative (`agreement` < 0), so that unfolding it lowers E.
double energy(const Points3Ref& ends, const FacesRef& faces, const std::vector<double>& scale,
              const std::vector<double>& agreement) {
  return tbb::parallel_reduce(
      tbb::blocked_range<Index>(0, faces.rows(), 4096), 0.0,
      [&](const tbb::blocked_range<Index>& range, double sum) {
        for (Index f = range.begin(); f < range.end(); ++f) {
          if (scale[static_cast<std::size_t>(f)] == 0) continue;
          double r = twice_area(corner(ends, faces, f, 0), corner(ends, faces, f, 1), corner(ends, faces, f, 2)) *
                     scale[static_cast<std::size_t>(f)];
          const bool folded = agreement[static_cast<std::size_t>(f)] < 0;
          if (folded) r = -r;
          sum += (folded ? kFoldWeight : 1.0) * (r - 1) * (r - 1);
        }
        return sum;
      },
      [](double a, double b) { return a + b; });
}

using Triplet = Eigen::Triplet<double>;
using Sparse = Eigen::SparseMatrix<double>;

// J^T J and J^T (r - 1) of the residuals in the ends' tangent coordinates (unknowns 2v, 2v + 1).
void normal_equations(const Points3Ref& current, const FacesRef& faces, const std::vector<double>& scale,
                      const std::vector<double>& agreement, const std::vector<Tangents>& basis,
                      std::vector<Triplet>& entries, Eigen::VectorXd& rhs) {
  const Index count = faces.rows();
  entries.assign(static_cast<std::size_t>(count) * 36, Triplet(0, 0, 0.0));
  std::vector<Eigen::Matrix<double, 6, 1>> pulls(static_cast<std::size_t>(count));
  tbb::parallel_for(tbb::blocked_range<Index>(0, count, 1024), [&](const tbb::blocked_range<Index>& range) {
    for (Index f = range.begin(); f < range.end(); ++f) {
      const double s = scale[static_cast<std::size_t>(f)];
      Eigen::Matrix<double, 6, 1> row = Eigen::Matrix<double, 6, 1>::Zero();
      double residual = 0.0;
      if (s > 0) {
        const V3 q[3] = {corner(current, faces, f, 0), corner(current, faces, f, 1), corner(current, faces, f, 2)};
        const V3 cross = (q[1] - q[0]).cross(q[2] - q[0]);
        const double twice = cross.norm();
        if (twice > 0) {
          // A folded triangle's signed ratio is -r, its gradient -dr: the step turns it back.
          const double sign = agreement[static_cast<std::size_t>(f)] < 0 ? -1.0 : 1.0;
          const double weight = sign < 0 ? std::sqrt(kFoldWeight) : 1.0;
          residual = weight * (sign * twice * s - 1.0);
          for (int i = 0; i < 3; ++i) {
            const V3 d_ratio = weight * sign * s * (cross / twice).cross(q[(i + 2) % 3] - q[(i + 1) % 3]);
            row.segment<2>(2 * i) = basis[static_cast<std::size_t>(faces(f, i))].transpose() * d_ratio;
          }
        }
      }
      pulls[static_cast<std::size_t>(f)] = residual * row;
      const std::size_t at = static_cast<std::size_t>(f) * 36;
      for (int a = 0; a < 6; ++a) {
        for (int b = 0; b < 6; ++b) {
          entries[at + static_cast<std::size_t>(6 * a + b)] =
              Triplet(2 * faces(f, a / 2) + a % 2, 2 * faces(f, b / 2) + b % 2, row(a) * row(b));
        }
      }
    }
  });
  rhs.setZero();
  for (Index f = 0; f < count; ++f) {
    for (int a = 0; a < 6; ++a) rhs(2 * faces(f, a / 2) + a % 2) -= pulls[static_cast<std::size_t>(f)](a);
  }
}

// The graph Laplacian of the faces' edges plus eps times the identity, in the ends' tangent
// coordinates: sum over edges of |B_i x_i - B_k x_k|^2 + eps sum |x_i|^2.
void damping(const FacesRef& faces, const std::vector<Tangents>& basis, double eps, std::vector<Triplet>& entries) {
  entries.clear();
  entries.reserve(static_cast<std::size_t>(faces.rows()) * 24 + basis.size() * 2);
  for (Index f = 0; f < faces.rows(); ++f) {
    for (int e = 0; e < 3; ++e) {
      const Index i = faces(f, e), k = faces(f, (e + 1) % 3);
      const Eigen::Matrix2d off = -basis[static_cast<std::size_t>(i)].transpose() * basis[static_cast<std::size_t>(k)];
      for (int a = 0; a < 2; ++a) {
        entries.emplace_back(2 * i + a, 2 * i + a, 1.0);
        entries.emplace_back(2 * k + a, 2 * k + a, 1.0);
        for (int b = 0; b < 2; ++b) {
          entries.emplace_back(2 * i + a, 2 * k + b, off(a, b));
          entries.emplace_back(2 * k + b, 2 * i + a, off(a, b));
        }
      }
    }
  }
  for (std::size_t v = 0; v < 2 * basis.size(); ++v) {
    entries.emplace_back(static_cast<Index>(v), static_cast<Index>(v), eps);
  }
}

// Lowers `share` (each end's fraction of its `step`) until no triangle's image, moved straight
// along the steps, passes through zero area on the way: per triangle, the signed twice-area along
// its current normal is a quadratic in the fraction t, c + b t + a t^2 with c > 0; where it has a
// root t0 <= 1, the triangle's corners take 0.8 t0 of their shares, whose quadratic then has its
// root beyond 1. A corner shared with a triangle already passed may make that one fold again, so
// the pass repeats (a few times: each only lowers shares). The projection onto S2 afterwards is
// checked by the fold test; this spares that test most of its rejections (the analytic bound of
// locally injective parameterisation methods).
void limit_shares(const Points3Ref& current, const Points3& step, const FacesRef& faces,
                  const std::vector<double>& agreement, std::vector<double>& share) {
  for (int pass = 0; pass < 8; ++pass) {
    bool lowered = false;
    for (Index f = 0; f < faces.rows(); ++f) {
      if (agreement[static_cast<std::size_t>(f)] < 0) continue;  // folded: through zero is the way back
      const Index i0 = faces(f, 0), i1 = faces(f, 1), i2 = faces(f, 2);
      const V3 q0 = current.row(i0).transpose(), q1 = current.row(i1).transpose(), q2 = current.row(i2).transpose();
      const V3 e1 = q1 - q0, e2 = q2 - q0;
      const V3 normal = e1.cross(e2);
      const double c = normal.norm();
      if (!(c > 0)) continue;
      const V3 n = normal / c;
      const auto moved = [&](Index v) { return V3(share[static_cast<std::size_t>(v)] * step.row(v).transpose()); };
      const V3 d0 = moved(i0), d1 = moved(i1) - d0, d2 = moved(i2) - d0;
      const double b = (e1.cross(d2) + d1.cross(e2)).dot(n), a = d1.cross(d2).dot(n);
      // The smallest root in (0, 1] of c + b t + a t^2, if any.
      double root = 2.0;
      if (std::abs(a) < 1e-14 * std::max(c, std::abs(b))) {
        if (b < 0) root = -c / b;
      } else {
        const double disc = b * b - 4 * a * c;
        if (disc >= 0) {
          const double sq = std::sqrt(disc);
          for (const double t : {(-b - sq) / (2 * a), (-b + sq) / (2 * a)}) {
            if (t > 0 && t < root) root = t;
          }
        }
      }
      if (root > 1) continue;
      for (const Index v : {i0, i1, i2}) share[static_cast<std::size_t>(v)] *= 0.8 * root;
      lowered = true;
    }
    if (!lowered) return;
  }
}

}  // namespace

Points3 even_ends(const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces, const FoldTest& test,
                  const Points3Ref& v2, const FacesRef& f2, const SurfaceIndex& index2, double alpha,
                  const EvenOptions& options) {
  const Index count = starts.rows();
  // 1 / (alpha * twice the start area) per triangle (0 for a flat one, which the energy leaves out).
  std::vector<double> scale(static_cast<std::size_t>(faces.rows()), 0.0);
  for (Index f = 0; f < faces.rows(); ++f) {
    const double a = twice_area(corner(starts, faces, f, 0), corner(starts, faces, f, 1), corner(starts, faces, f, 2));
    if (a > 0) scale[static_cast<std::size_t>(f)] = 1.0 / (alpha * a);
  }
  const Points3 normals2 = unit_face_normals(v2, f2);
  std::vector<Index> every(static_cast<std::size_t>(faces.rows()));
  for (Index f = 0; f < faces.rows(); ++f) every[static_cast<std::size_t>(f)] = f;
  // The ends as given (on S2 already: projected again, a nearly flat triangle's orientation may
  // turn), with the triangles of S2 they lie on.
  SurfaceHits on = index2.closest_points(ends);
  Points3 current = ends;
  // A triangle flat on either side at the start (agreement 0) may stay so, one folded at the start
  // may turn either way; every other must keep its orientation.
  const std::vector<double> before = test.agreement(current, every);
  std::vector<double> now = before;
  double e = energy(current, faces, scale, now);

  std::vector<Tangents> basis(static_cast<std::size_t>(count));
  std::vector<Triplet> entries, smooth;
  Eigen::VectorXd rhs(2 * count);
  Sparse gauss(2 * count, 2 * count), laplace(2 * count, 2 * count);
  Eigen::SimplicialLDLT<Sparse> solver;
  bool analysed = false;
  std::vector<double> history{e};  // the energy after each accepted step
  // The ends that stay: the caller's, and the corners of a triangle flat at the start that a step
  // would turn.
  std::vector<char> held = options.fixed;
  held.resize(static_cast<std::size_t>(count), 0);
  double lambda = 1.0;  // of the damping, relative to J^T J's mean diagonal over L's
  for (int iteration = 0; iteration < options.max_iterations && e > 0; ++iteration) {
    check_interrupt();
    for (Index v = 0; v < count; ++v)
      basis[static_cast<std::size_t>(v)] = tangent_frame(normals2.row(on.faces(v)).transpose());
    normal_equations(current, faces, scale, now, basis, entries, rhs);
    gauss.setFromTriplets(entries.begin(), entries.end());
    damping(faces, basis, 1e-3, smooth);
    laplace.setFromTriplets(smooth.begin(), smooth.end());
    const double ratio = gauss.diagonal().mean() / std::max(laplace.diagonal().mean(), 1e-300);
    bool accepted = false;
    for (int tries = 0; tries < 8 && !accepted; ++tries) {
      const Sparse system = gauss + (lambda * ratio) * laplace;
      if (!analysed) {
        solver.analyzePattern(system);
        analysed = true;
      }
      solver.factorize(system);
      if (solver.info() != Eigen::Success) {
        lambda *= 10;
        continue;
      }
      const Eigen::VectorXd x = solver.solve(rhs);
      Points3 step(count, 3);
      for (Index v = 0; v < count; ++v) {
        step.row(v) = (basis[static_cast<std::size_t>(v)] * x.segment<2>(2 * v)).transpose();
      }
      std::vector<double> share(static_cast<std::size_t>(count));
      for (std::size_t v = 0; v < share.size(); ++v) share[v] = held[v] ? 0.0 : 1.0;
      limit_shares(current, step, faces, now, share);
      int shrinks = 0;  // halvings of every share because the energy did not fall
      for (int attempt = 0; attempt < 12 && !accepted; ++attempt) {
        Points3 tried = current;
        for (Index v = 0; v < count; ++v) tried.row(v) += share[static_cast<std::size_t>(v)] * step.row(v);
        SurfaceHits moved = index2.closest_points(tried);
        for (Index v = 0; v < count; ++v) {  // an end held stays exactly (a projection may move it an ulp)
          if (share[static_cast<std::size_t>(v)] == 0) {
            moved.points.row(v) = current.row(v);
            moved.faces(v) = on.faces(v);
          }
        }
        const std::vector<double> agreement = test.agreement(moved.points, every);
        bool folds = false;
        for (std::size_t j = 0; j < agreement.size(); ++j) {
          if ((agreement[j] < 0 && before[j] >= 0) || (agreement[j] == 0 && before[j] > 0) ||
              std::isnan(agreement[j])) {
            folds = true;
            // Its corners stay for this step; those of a triangle flat at the start (no orientation
            // to keep, so any move may turn it) stay for good.
            for (int i = 0; i < 3; ++i) {
              double& s = share[static_cast<std::size_t>(faces(static_cast<Index>(j), i))];
              if (before[j] == 0) held[static_cast<std::size_t>(faces(static_cast<Index>(j), i))] = 1;
              s = 0.0;
            }
          }
        }
        if (folds) continue;
        const double e_new = energy(moved.points, faces, scale, agreement);
        if (!(e_new < e)) {
          for (double& s : share) s *= 0.5;
          ++shrinks;
          continue;
        }
        current = std::move(moved.points);
        on = std::move(moved);
        now = agreement;
        e = e_new;
        accepted = true;
        // The model was good (a full step lowered the energy): trust it further; it was poor (the
        // step had to shrink twice or more): damp more.
        lambda = shrinks == 0 ? std::max(lambda / 3, 1e-6) : shrinks >= 2 ? lambda * 4 : lambda;
        history.push_back(e);
        const bool unfolded = std::none_of(now.begin(), now.end(), [](double a) { return a < 0; });
        if (unfolded && options.until_unfolded) return current;
        if (unfolded && history.size() > kWindow && history[history.size() - 1 - kWindow] - e < options.tolerance * e)
          return current;
      }
      if (!accepted) lambda *= 10;
    }
    if (!accepted) break;
  }
  return current;
}

}  // namespace morphomap::detail
