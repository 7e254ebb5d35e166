// The energy. Each triangle j maps its start, flattened and scaled by sqrt(alpha) (reference
// edges R_j), onto its image seen in a plane normal to S2 under it (edges U_j): J = U_j R_j^-1,
// D = det J the image's area over alpha times the start's, signed by its orientation on S2. With
// chi(D, eps) = (D + sqrt(eps^2 + D^2)) / 2 > 0, a smooth stand-in for max(D, 0),
//   f_eps(J) = ((1 - theta) |J|^2 + theta (D^2 + 1)) / (2 chi(D, eps)),
// whose minimum over J is 1, at a rotation; as eps falls to 0 it grows without bound where D
// nears 0 from above and is infinite where D <= 0. E = sum_j w_j f_eps(J_j), w_j the start's
// share of the area. Each round minimises E at one eps by L-BFGS: the ends move within S2's
// tangent planes and return onto S2 by closest point, every step found by a backtracking line
// search on E after that projection. Between rounds eps falls as Garanzha et al. lower it: with
// D- the smallest D and sigma = max(1 - E / E_before, 1/10) the round's relative progress,
// mu = (1 - sigma) chi(D-, eps); eps = 2 sqrt(mu (mu - D-)) where D- < mu, else almost 0.
// Frames: first each image's plane follows the sum of S2's normals under its corners at every
// evaluation, so that E is one function of the ends (voxelised limb 270 -> 250 h: QM 0.56 against
// 3.43 with frames held); where that does not untangle (unblurred 290 -> 250 h), the frames are
// taken once a round, under the centroid too, as the fold test takes them (bench/README.md "Real
// 3D stages"). The ends' tangent planes are those of S2's faces under them.
#include "mapping/barrier_untangle.hpp"

#include "common/interrupt_check.hpp"
#include "quality/folds.hpp"
#include "surfaces/surface_util.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <numeric>
#include <optional>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace morphomap::detail {
namespace {

using M2 = Eigen::Matrix2d;
using Frame = Eigen::Matrix<double, 3, 2>;

// The share of shape against area in f: equal, so the untangled images keep their starts' shape
// as much as their share of S2's area.
constexpr double kShape = 0.5;
// L-BFGS: the pairs of steps remembered, the iterations of one round, and the line search's
// halvings of one step.
constexpr int kMemory = 8;
constexpr int kIterations = 60;
constexpr int kHalvings = 20;
// A step moves no end further than this fraction of the triangles' typical (scaled) start edge,
// so that the projection back onto S2 stays on the sheet the end is on.
constexpr double kReach = 0.5;
// The regularisation once no triangle is near zero area.
constexpr double kLeast = 1e-9;

// chi and its slope, for d < 0 in the forms without cancellation: where a sliver's image has
// turned (D of -1e14 on a capped fuzz frame) the plain sum rounds to 0 and the energy to infinity.
double chi(double d, double eps) {
  const double r = std::sqrt(eps * eps + d * d);
  return d >= 0 ? 0.5 * (d + r) : 0.5 * eps * eps / (r - d);
}
double chi_slope(double d, double eps) {
  const double r = std::sqrt(eps * eps + d * d);
  return d >= 0 ? 0.5 * (1.0 + d / r) : 0.5 * eps * eps / ((r - d) * r);
}

// An image below this share of its start's area times alpha does not count as untangled: the
// fold test finds no orientation in an image of no area (a flat triangle is not folded), and two
// boxes that only touch had every end drawn into one point before this bound.
constexpr double kLeastImage = 1e-6;

struct Triangle {
  Index corner[3];
  M2 inverse;     // R^-1, the inverse of the scaled start's edge matrix in its own plane
  double weight;  // the start's share of the area of all the triangles untangled
  double least;   // the smallest area its image may have: kLeastImage alpha times the start's
  Frame frame;    // two unit vectors spanning the plane normal to S2 under the image, in order
};

// The triangles touching a moving end, with their reference shapes (starts of no area left out).
std::vector<Triangle> triangles_of(const Points3Ref& starts, const FacesRef& faces, const std::vector<char>& fixed,
                                   double alpha, double& typical_edge) {
  std::vector<Triangle> out;
  std::vector<double> edges;
  double total = 0.0;
  for (Index f = 0; f < faces.rows(); ++f) {
    if (fixed[faces(f, 0)] && fixed[faces(f, 1)] && fixed[faces(f, 2)]) continue;
    const V3 a = corner(starts, faces, f, 0), e1 = corner(starts, faces, f, 1) - a,
             e2 = corner(starts, faces, f, 2) - a;
    const V3 n = e1.cross(e2);
    if (!(n.norm() > 0)) continue;
    const V3 x = e1.normalized(), y = n.normalized().cross(x);
    M2 r;
    r << e1.norm(), e2.dot(x), 0.0, e2.dot(y);
    r *= std::sqrt(alpha);
    // A start with no height left after rounding (a cap's sliver) has no shape to keep: left out
    // as the fold test leaves out a flat one.
    if (!(r(1, 1) > 0) || !r.inverse().allFinite()) continue;
    Triangle t{{faces(f, 0), faces(f, 1), faces(f, 2)},
               r.inverse(),
               0.5 * n.norm(),
               kLeastImage * alpha * 0.5 * n.norm(),
               Frame::Zero()};
    total += t.weight;
    out.push_back(t);
    edges.push_back(std::sqrt(alpha) * e1.norm());
  }
  for (Triangle& t : out) t.weight /= total;
  typical_edge = 0.0;
  if (!edges.empty()) {
    std::nth_element(edges.begin(), edges.begin() + static_cast<std::ptrdiff_t>(edges.size() / 2), edges.end());
    typical_edge = edges[edges.size() / 2];
  }
  return out;
}

// The frame of an image: normal to `sum`, the sum of S2's unit face normals under it (any frame
// where they cancel).
Frame frame_normal_to(const V3& sum) { return tangent_frame(sum.norm() > 0 ? V3(sum.normalized()) : V3::UnitZ()); }

// `sum` plus S2's unit normals (`normals2`, per face) under a triangle's corners (`under`: the
// face of S2 each end lies on).
V3 normals_under_corners(const Triangle& t, const IndexVector& under, const Points3& normals2, V3 sum = V3::Zero()) {
  for (const Index c : t.corner) sum += normals2.row(under(c)).transpose();
  return sum;
}

// Each triangle's frame from S2's normals under its centroid and its corners, as the fold test
// orients it.
void refresh_frames(std::vector<Triangle>& tris, const Points3& x, const IndexVector& under, const Points3& normals2,
                    const SurfaceIndex& index2) {
  Points3 centroids(static_cast<Index>(tris.size()), 3);
  for (std::size_t k = 0; k < tris.size(); ++k) {
    const Triangle& t = tris[k];
    centroids.row(static_cast<Index>(k)) = (x.row(t.corner[0]) + x.row(t.corner[1]) + x.row(t.corner[2])) / 3.0;
  }
  const IndexVector centre = index2.closest_points(centroids).faces;
  for (std::size_t k = 0; k < tris.size(); ++k) {
    Triangle& t = tris[k];
    t.frame = frame_normal_to(
        normals_under_corners(t, under, normals2, normals2.row(centre(static_cast<Index>(k))).transpose()));
  }
}

// Each triangle's frame from S2's normals under its corners alone, as they move: no query, so
// it can follow the ends at every evaluation.
void corner_frames(std::vector<Triangle>& tris, const IndexVector& under, const Points3& normals2) {
  for (Triangle& t : tris) t.frame = frame_normal_to(normals_under_corners(t, under, normals2));
}

// E at x, its gradient with respect to every end (where `gradient`), and the smallest D.
double energy(const std::vector<Triangle>& tris, const Points3& x, double eps, Points3* gradient, double& least) {
  std::vector<double> values(tris.size());
  std::vector<double> dets(tris.size());
  std::vector<Eigen::Matrix3d> pulls(gradient != nullptr ? tris.size() : 0);
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, tris.size(), 512), [&](const tbb::blocked_range<std::size_t>& r) {
        for (std::size_t k = r.begin(); k < r.end(); ++k) {
          const Triangle& t = tris[k];
          const V3 q0 = x.row(t.corner[0]).transpose();
          M2 u;
          u.col(0) = t.frame.transpose() * (x.row(t.corner[1]).transpose() - q0);
          u.col(1) = t.frame.transpose() * (x.row(t.corner[2]).transpose() - q0);
          const M2 j = u * t.inverse;
          const double d = j.determinant(), c = chi(d, eps);
          const double top = (1.0 - kShape) * j.squaredNorm() + kShape * (d * d + 1.0);
          const double f = top / (2.0 * c);
          values[k] = t.weight * f;
          dets[k] = d;
          if (gradient == nullptr) continue;
          M2 cofactor;
          cofactor << j(1, 1), -j(1, 0), -j(0, 1), j(0, 0);
          const M2 d_j = ((1.0 - kShape) * j + kShape * d * cofactor) / c - (f * chi_slope(d, eps) / c) * cofactor;
          const M2 d_u = t.weight * d_j * t.inverse.transpose();
          Eigen::Matrix3d p;
          p.col(1) = t.frame * d_u.col(0);
          p.col(2) = t.frame * d_u.col(1);
          p.col(0) = -p.col(1) - p.col(2);
          pulls[k] = p;
        }
      });
  least = dets.empty() ? 0.0 : *std::min_element(dets.begin(), dets.end());
  if (gradient != nullptr) {
    gradient->setZero(x.rows(), 3);
    for (std::size_t k = 0; k < tris.size(); ++k) {
      for (int i = 0; i < 3; ++i) gradient->row(tris[k].corner[i]) += pulls[k].col(i).transpose();
    }
  }
  return std::accumulate(values.begin(), values.end(), 0.0);
}

}  // namespace

std::optional<Points3> barrier_untangled(const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces,
                                         const FoldTest& test, const std::vector<char>& fixed, const FacesRef& f2,
                                         const Points3Ref& v2, const SurfaceIndex& index2, double alpha, int rounds) {
  double edge = 0.0;
  std::vector<Triangle> tris = triangles_of(starts, faces, fixed, alpha, edge);
  std::vector<Index> moving, involved;
  for (Index v = 0; v < starts.rows(); ++v) {
    if (!fixed[static_cast<std::size_t>(v)]) moving.push_back(v);
  }
  for (Index f = 0; f < faces.rows(); ++f) {
    if (!(fixed[faces(f, 0)] && fixed[faces(f, 1)] && fixed[faces(f, 2)])) involved.push_back(f);
  }
  const Index m = static_cast<Index>(moving.size());
  if (tris.empty() || m == 0 || !(edge > 0)) return std::nullopt;
  const Points3 normals2 = unit_face_normals(v2, f2);  // once: the frames take them at every evaluation
  // Untangled: no triangle folded, and every image of a start with area keeps some area.
  const auto untangled_at = [&](const Points3& at) {
    const std::vector<double> a = test.agreement(at, involved);
    if (std::any_of(a.begin(), a.end(), [](double v) { return v < 0; })) return false;
    return std::all_of(tris.begin(), tris.end(), [&](const Triangle& t) {
      const V3 q0 = at.row(t.corner[0]).transpose();
      return 0.5 * (at.row(t.corner[1]).transpose() - q0).cross(at.row(t.corner[2]).transpose() - q0).norm() > t.least;
    });
  };
  // One way of taking the frames: following the ends (E one function of them; the lower QM where
  // it untangles) or once a round with the centroid's face too (bench/README.md "Real 3D stages").
  const auto attempt = [&](bool follow) -> std::optional<Points3> {
    SurfaceHits on = index2.closest_points(ends);
    Points3 x = ends;
    // The moving ends' gradient within S2's tangent plane at each, as one vector.
    Points3 gradient;
    const auto tangential = [&](const Points3& g, const IndexVector& under) {
      Eigen::VectorXd out(3 * m);
      for (Index k = 0; k < m; ++k) {
        const V3 n = normals2.row(under(moving[static_cast<std::size_t>(k)])).transpose();
        const V3 d = g.row(moving[static_cast<std::size_t>(k)]).transpose();
        out.segment<3>(3 * k) = d - n * n.dot(d);
      }
      return out;
    };
    double least = 0.0;
    const auto set_frames = [&](const Points3& at, const IndexVector& under) {
      if (follow)
        corner_frames(tris, under, normals2);
      else
        refresh_frames(tris, at, under, normals2, index2);
    };
    set_frames(x, on.faces);
    energy(tris, x, 1.0, nullptr, least);
    double eps = std::max(1.0, 2.0 * std::abs(least));
    for (int round = 0; round < rounds; ++round) {
      check_interrupt();
      set_frames(x, on.faces);
      double e = energy(tris, x, eps, &gradient, least);
      const double e_before = e;
      Eigen::VectorXd g = tangential(gradient, on.faces);
      std::deque<std::pair<Eigen::VectorXd, Eigen::VectorXd>> memory;  // (s, y) pairs
      for (int iteration = 0; iteration < kIterations; ++iteration) {
        // The L-BFGS direction (two-loop recursion), else steepest descent.
        Eigen::VectorXd d = -g;
        std::vector<double> rho(memory.size()), a(memory.size());
        for (std::size_t i = memory.size(); i-- > 0;) {
          rho[i] = 1.0 / memory[i].second.dot(memory[i].first);
          a[i] = rho[i] * memory[i].first.dot(d);
          d -= a[i] * memory[i].second;
        }
        if (!memory.empty()) d *= memory.back().first.dot(memory.back().second) / memory.back().second.squaredNorm();
        for (std::size_t i = 0; i < memory.size(); ++i)
          d += (a[i] - rho[i] * memory[i].second.dot(d)) * memory[i].first;
        if (!(d.dot(g) < 0)) d = -g, memory.clear();
        if (!d.allFinite()) break;  // a slope that overflowed (a sliver against a huge image)
        double longest = 0.0;
        for (Index k = 0; k < m; ++k) longest = std::max(longest, d.segment<3>(3 * k).norm());
        if (!(longest > 0)) break;
        double step = std::min(1.0, kReach * edge / longest);
        const double slope = d.dot(g);
        bool accepted = false;
        for (int halving = 0; halving < kHalvings && !accepted; ++halving, step *= 0.5) {
          Points3 tried = x;
          for (Index k = 0; k < m; ++k)
            tried.row(moving[static_cast<std::size_t>(k)]) += step * d.segment<3>(3 * k).transpose();
          if (!tried.allFinite()) continue;
          const SurfaceHits placed = index2.closest_points(tried(moving, Eigen::all));
          for (Index k = 0; k < m; ++k) tried.row(moving[static_cast<std::size_t>(k)]) = placed.points.row(k);
          IndexVector under = on.faces;
          for (Index k = 0; k < m; ++k) under(moving[static_cast<std::size_t>(k)]) = placed.faces(k);
          if (follow) set_frames(tried, under);
          Points3 g_new;
          double least_new = 0.0;
          const double e_new = energy(tris, tried, eps, &g_new, least_new);
          if (!(e_new <= e + 1e-4 * step * slope) || !g_new.allFinite()) continue;
          accepted = true;
          const Eigen::VectorXd g_next = tangential(g_new, under);
          Eigen::VectorXd s(3 * m);
          for (Index k = 0; k < m; ++k) {
            const Index v = moving[static_cast<std::size_t>(k)];
            s.segment<3>(3 * k) = (tried.row(v) - x.row(v)).transpose();
          }
          const Eigen::VectorXd y = g_next - g;
          if (s.dot(y) > 1e-12 * s.norm() * y.norm()) {
            memory.emplace_back(s, y);
            if (static_cast<int>(memory.size()) > kMemory) memory.pop_front();
          }
          x = std::move(tried);
          on.faces = std::move(under);
          g = g_next;
          e = e_new;
          least = least_new;
        }
        if (!accepted) break;
      }
      if (untangled_at(x)) return x;
      const double sigma = std::max(1.0 - e / e_before, 0.1);
      const double mu = (1.0 - sigma) * chi(least, eps);
      eps = least < mu ? 2.0 * std::sqrt(mu * (mu - least)) : kLeast;
    }
    return std::nullopt;
  };
  for (const bool follow : {true, false}) {
    if (std::optional<Points3> untangled = attempt(follow)) return untangled;
  }
  return std::nullopt;
}

}  // namespace morphomap::detail
