// The energy and its steps. With r_j = A'_j / (alpha A_j) the area ratio of triangle j against
// the surfaces' own, E = sum_j (r_j - 1)^2 is zero exactly where every triangle's image keeps its
// share of S2's area (the radial map between concentric spheres, any similarity), and it is QM1
// of the 3D quality measure, so lowering it is what makes the field even. Its gradient at end q_i
// of triangle j is 2 (r_j - 1) / (alpha A_j) * dA'_j/dq_i, with dA'/dq_i = n' x (q_l - q_k) / 2 (n'
// the image's unit normal, (i, k, l) in order round it). A step moves every end at once by minus
// its gradient over a diagonal curvature (the sum over its triangles of the squared gradients of
// their terms: a Gauss-Newton step per end), within S2's tangent plane, then onto S2 by closest
// point. A flip-preventing line search, as locally injective parameterisation methods use: an
// end's share of the step is quartered at the corners of a triangle the step would fold, and every
// share halved while the energy does not fall. The caller starts from auto's field, complete and
// fold-free; every step keeps it so.
#include "mapping/even_surface.hpp"

#include "common/interrupt_check.hpp"
#include "quality/folds.hpp"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace morphomap::detail {
namespace {

using V3 = Eigen::Vector3d;

V3 corner(const Points3Ref& points, const FacesRef& faces, Index f, int i) {
  return points.row(faces(f, i)).transpose();
}

double twice_area(const V3& a, const V3& b, const V3& c) { return (b - a).cross(c - a).norm(); }

// Each vertex's triangles (compressed rows: first[v] .. first[v + 1]).
struct Around {
  std::vector<Index> first, faces;
  Around(const FacesRef& f, Index vertices) : first(static_cast<std::size_t>(vertices) + 1, 0) {
    for (Index k = 0; k < f.rows(); ++k) {
      for (int i = 0; i < 3; ++i) ++first[static_cast<std::size_t>(f(k, i)) + 1];
    }
    std::partial_sum(first.begin(), first.end(), first.begin());
    faces.resize(static_cast<std::size_t>(first.back()));
    std::vector<Index> next(first.begin(), first.end() - 1);
    for (Index k = 0; k < f.rows(); ++k) {
      for (int i = 0; i < 3; ++i) faces[static_cast<std::size_t>(next[static_cast<std::size_t>(f(k, i))]++)] = k;
    }
  }
};

double energy(const Points3Ref& ends, const FacesRef& faces, const std::vector<double>& scale) {
  return tbb::parallel_reduce(
      tbb::blocked_range<Index>(0, faces.rows(), 4096), 0.0,
      [&](const tbb::blocked_range<Index>& range, double sum) {
        for (Index f = range.begin(); f < range.end(); ++f) {
          if (scale[static_cast<std::size_t>(f)] == 0) continue;
          const double r = twice_area(corner(ends, faces, f, 0), corner(ends, faces, f, 1), corner(ends, faces, f, 2)) *
                           scale[static_cast<std::size_t>(f)];
          sum += (r - 1) * (r - 1);
        }
        return sum;
      },
      [](double a, double b) { return a + b; });
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
  Points3 normals2(f2.rows(), 3);
  for (Index f = 0; f < f2.rows(); ++f) {
    const V3 n = (corner(v2, f2, f, 1) - corner(v2, f2, f, 0)).cross(corner(v2, f2, f, 2) - corner(v2, f2, f, 0));
    normals2.row(f) = (n.norm() > 0 ? V3(n.normalized()) : V3::Zero()).transpose();
  }
  const Around around(faces, count);
  std::vector<Index> every(static_cast<std::size_t>(faces.rows()));
  std::iota(every.begin(), every.end(), Index{0});
  SurfaceHits on = index2.closest_points(ends);
  Points3 current = on.points;
  double e = energy(current, faces, scale);
  // A triangle flat on either side at the start (agreement 0) may stay so; every other must keep
  // its orientation.
  const std::vector<double> before = test.agreement(current, every);
  Points3 step(count, 3);
  for (int iteration = 0; iteration < options.max_iterations && e > 0; ++iteration) {
    check_interrupt();
    tbb::parallel_for(tbb::blocked_range<Index>(0, count, 1024), [&](const tbb::blocked_range<Index>& range) {
      for (Index v = range.begin(); v < range.end(); ++v) {
        V3 gradient = V3::Zero();
        double curvature = 0.0;
        for (Index k = around.first[static_cast<std::size_t>(v)]; k < around.first[static_cast<std::size_t>(v) + 1];
             ++k) {
          const Index f = around.faces[static_cast<std::size_t>(k)];
          const double s = scale[static_cast<std::size_t>(f)];
          if (s == 0) continue;
          int i = 0;
          while (faces(f, i) != v) ++i;
          const V3 q = corner(current, faces, f, i), qk = corner(current, faces, f, (i + 1) % 3),
                   ql = corner(current, faces, f, (i + 2) % 3);
          const V3 cross = (qk - q).cross(ql - q);
          const double twice = cross.norm();
          if (!(twice > 0)) continue;
          const V3 d_area = 0.5 * (cross / twice).cross(ql - qk);  // dA'/dq
          const V3 d_ratio = 2.0 * s * d_area;                     // d r_j / dq (r = 2A' s)
          gradient += 2.0 * (twice * s - 1.0) * d_ratio;
          curvature += 2.0 * d_ratio.squaredNorm();
        }
        // Within S2's tangent plane at the end (its triangle's normal).
        const V3 n = normals2.row(on.faces(v)).transpose();
        gradient -= gradient.dot(n) * n;
        step.row(v) = (curvature > 0 ? V3(-gradient / curvature) : V3::Zero()).transpose();
      }
    });
    // Each end's share of the step: quartered at the corners of a triangle it would fold (so one
    // tight spot does not hold every end back), all halved while the energy does not fall.
    std::vector<double> share(static_cast<std::size_t>(count), 1.0);
    bool accepted = false;
    for (int attempt = 0; attempt < 16 && !accepted; ++attempt) {
      Points3 tried = current;
      for (Index v = 0; v < count; ++v) tried.row(v) += share[static_cast<std::size_t>(v)] * step.row(v);
      SurfaceHits moved = index2.closest_points(tried);
      const std::vector<double> agreement = test.agreement(moved.points, every);
      bool folds = false;
      for (std::size_t j = 0; j < agreement.size(); ++j) {
        if (agreement[j] < 0 || (agreement[j] == 0 && before[j] > 0) || std::isnan(agreement[j])) {
          folds = true;
          for (int i = 0; i < 3; ++i) share[static_cast<std::size_t>(faces(static_cast<Index>(j), i))] *= 0.25;
        }
      }
      if (folds) continue;
      const double e_new = energy(moved.points, faces, scale);
      if (!(e_new < e)) {
        for (double& s : share) s *= 0.5;
        continue;
      }
      const double gain = (e - e_new) / e;
      current = std::move(moved.points);
      on = std::move(moved);
      e = e_new;
      accepted = gain >= options.tolerance;
      if (!accepted) break;
    }
    if (!accepted) break;
  }
  return current;
}

}  // namespace morphomap::detail
