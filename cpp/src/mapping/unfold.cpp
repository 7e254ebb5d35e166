// Repair of the few triangles that diffusion mapping folds in 3D.
//
// The streamlines of the continuous flow never cross, so the exact diffusion map keeps every
// triangle's orientation; the discrete one carries errors of the order of the tetrahedral mesh's
// distance to the surfaces, and a sliver of S1 narrower than that (marching cubes makes them) can
// come out flipped (one 0.02 wide against the mesh's distance to the surfaces of 0.05; the fuzz
// frames that did so are pinned in tests/test_real_frames.py). A corner of a folded triangle is
// moved into the kernel of its image fan: the part of S2's tangent plane from which every triangle
// around it is seen with its orientation on S1 (the intersection of one half-plane per triangle),
// near the kernel's point closest to where it was; then onto S2. Where triangles stay folded the
// region grows by a ring and the step repeats, a few times at most; a round is kept only when it
// leaves fewer folds, and what is left stays folded and is counted by quality().
//
// Where an image fan straddles a crease of a voxel-made S2 no single tangent plane may hold a
// kernel (a triangle's image may lie across a right-angled edge of S2, nearly perpendicular to the
// face under it). Before the kernel rounds and within each, the corners of the folded triangles
// therefore also try the umbrella step, towards the mean of their neighbours' ends, judged by the
// fold test itself (descend below).
#include "quality/folds.hpp"

#include "surfaces/surface_util.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <vector>

namespace morphomap::detail {

namespace {

using V2 = Eigen::Vector2d;
constexpr int kRounds = 6;
constexpr int kSweeps = 3;
constexpr double kInward = 0.2;

double cross2(const V2& a, const V2& b) { return a.x() * b.y() - a.y() * b.x(); }

// The part of `polygon` (convex, counter-clockwise) left of the directed line a -> b.
std::vector<V2> clip_left(const std::vector<V2>& polygon, const V2& a, const V2& b) {
  std::vector<V2> out;
  const V2 d = b - a;
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const V2& p = polygon[i];
    const V2& q = polygon[(i + 1) % polygon.size()];
    const double sp = cross2(d, p - a), sq = cross2(d, q - a);
    if (sp >= 0) out.push_back(p);
    if ((sp >= 0) != (sq >= 0)) out.push_back(p + (sp / (sp - sq)) * (q - p));
  }
  return out;
}

// Area centroid of a convex polygon; NaN when it has no area.
V2 centroid(const std::vector<V2>& polygon) {
  double area = 0.0;
  V2 sum = V2::Zero();
  for (std::size_t i = 1; i + 1 < polygon.size(); ++i) {
    const double a = cross2(polygon[i] - polygon[0], polygon[i + 1] - polygon[0]);
    area += a;
    sum += a * (polygon[0] + polygon[i] + polygon[i + 1]) / 3.0;
  }
  if (!(area > 0)) return V2::Constant(std::numeric_limits<double>::quiet_NaN());
  return sum / area;
}

// The new end of vertex v: inside the kernel of its fan (the triangles `around` it, each a
// row of `faces`) in the plane through its end with unit normal n, a fifth of the way from the
// kernel's point nearest the old end to its centre (so that a nearly flat triangle, whose sign
// is noise, opens up too); NaN when the kernel is empty.
V3 into_kernel(Index v, const std::vector<Index>& around, const FacesRef& faces, const Points3& ends, const V3& n) {
  const V3 origin = ends.row(v).transpose();
  const V3 t1 = n.unitOrthogonal(), t2 = n.cross(t1);
  auto flat = [&](Index w) {
    const V3 d = ends.row(w).transpose() - origin;
    return V2(d.dot(t1), d.dot(t2));
  };
  double reach = 0.0;
  std::vector<std::array<V2, 2>> edges;  // v must lie left of each, a -> b
  for (const Index j : around) {
    int k = 0;
    while (faces(j, k) != v) ++k;
    const Index a = faces(j, (k + 1) % 3), b = faces(j, (k + 2) % 3);
    // A triangle with a lost corner is no fold (quality leaves it out) and constrains nothing.
    if (!ends.row(a).allFinite() || !ends.row(b).allFinite()) continue;
    edges.push_back({flat(a), flat(b)});
    reach = std::max({reach, edges.back()[0].norm(), edges.back()[1].norm()});
  }
  const double r = 2.0 * reach;
  std::vector<V2> kernel = {V2(-r, -r), V2(r, -r), V2(r, r), V2(-r, r)};
  for (const auto& e : edges) {
    kernel = clip_left(kernel, e[0], e[1]);
    if (kernel.size() < 3) return V3::Constant(std::numeric_limits<double>::quiet_NaN());
  }
  const V2 c = centroid(kernel);
  if (!c.allFinite()) return V3::Constant(std::numeric_limits<double>::quiet_NaN());
  // As little motion as keeps clear of the kernel's edges: from the kernel's point nearest the
  // old end a fifth of the way towards its centre.
  V2 nearest = kernel[0];
  for (std::size_t i = 0; i < kernel.size(); ++i) {
    const V2 a = kernel[i], d = kernel[(i + 1) % kernel.size()] - a;
    const double t = d.squaredNorm() > 0 ? std::clamp(-a.dot(d) / d.squaredNorm(), 0.0, 1.0) : 0.0;
    if ((a + t * d).squaredNorm() < nearest.squaredNorm()) nearest = a + t * d;
  }
  const V2 chosen = nearest + kInward * (c - nearest);
  return origin + chosen.x() * t1 + chosen.y() * t2;
}

// Greedy moves judged by the fold test itself: each corner of a folded triangle tries the point
// of S2 closest to the mean of its neighbours' ends, and the point of S2 closest to halfway there;
// a move is kept only when its fan then has fewer folded triangles, or as many and a better worst
// one. A move changes only its own fan, so the folds never grow; the next sweep tries the corners
// of the triangles still folded in the fans that moved (their neighbours' means changed).
// `folded` (test.folded(ends) on entry) is kept so: each move retests the fan it changed.
void descend(const FoldTest& test, Points3& ends, std::vector<char>& folded, const FacesRef& faces,
             const std::vector<std::vector<Index>>& around, const SurfaceIndex& index2) {
  struct Score {
    Index folds = 0;
    double worst = 1.0;
    bool better_than(const Score& other) const {
      return folds < other.folds || (folds == other.folds && worst > other.worst);
    }
  };
  auto score = [&](Index v) {
    Score s;
    for (const double a : test.agreement(ends, around[v])) {
      if (std::isnan(a)) continue;
      s.folds += a < 0;
      s.worst = std::min(s.worst, a);
    }
    return s;
  };
  std::vector<char> corner(static_cast<std::size_t>(ends.rows()), 0);
  for (Index j = 0; j < faces.rows(); ++j) {
    if (!folded[j]) continue;
    for (int k = 0; k < 3; ++k) corner[faces(j, k)] = 1;
  }
  for (int sweep = 0; sweep < kSweeps; ++sweep) {
    std::vector<char> next(corner.size(), 0);
    bool moved = false;
    for (Index v = 0; v < ends.rows(); ++v) {
      if (!corner[v] || !ends.row(v).allFinite()) continue;
      V3 mean = V3::Zero();
      int count = 0;
      for (const Index j : around[v]) {
        for (int k = 0; k < 3; ++k) {
          const Index w = faces(j, k);
          if (w != v && ends.row(w).allFinite()) mean += ends.row(w).transpose(), ++count;
        }
      }
      if (count == 0) continue;
      mean /= count;  // a neighbour shared by two triangles counts twice: closer to the fan's middle
      const V3 old_end = ends.row(v).transpose();
      Points3 targets(2, 3);
      targets.row(0) = mean.transpose();
      targets.row(1) = (0.5 * (old_end + mean)).transpose();
      const Points3 candidates = index2.closest_points(targets).points;
      Score best = score(v);
      V3 chosen = old_end;
      for (Index c = 0; c < candidates.rows(); ++c) {
        ends.row(v) = candidates.row(c);
        const Score s = score(v);
        if (s.better_than(best)) best = s, chosen = candidates.row(c).transpose();
      }
      ends.row(v) = chosen.transpose();
      if (chosen == old_end) continue;
      moved = true;
      const std::vector<double> after = test.agreement(ends, around[v]);
      for (std::size_t i = 0; i < after.size(); ++i) {
        const Index j = around[v][i];
        folded[j] = after[i] < 0;
        if (!folded[j]) continue;
        for (int k = 0; k < 3; ++k) next[faces(j, k)] = 1;
      }
    }
    if (!moved) return;
    corner.swap(next);
  }
}

}  // namespace

Index unfold(const Points3Ref& starts, Points3& ends, const FacesRef& faces, const Points3Ref& v1, const FacesRef& f1,
             const SurfaceIndex& index1, const Points3Ref& v2, const FacesRef& f2, const SurfaceIndex& index2) {
  const FoldTest test(starts, faces, v1, f1, index1, v2, f2, index2);
  std::vector<char> folded = test.folded(ends);
  Index left = static_cast<Index>(std::count(folded.begin(), folded.end(), 1));
  if (left == 0) return 0;
  const Index n = starts.rows();
  std::vector<std::vector<Index>> around(n);  // the triangles at each vertex
  for (Index j = 0; j < faces.rows(); ++j) {
    for (int k = 0; k < 3; ++k) around[faces(j, k)].push_back(j);
  }
  descend(test, ends, folded, faces, around, index2);
  left = static_cast<Index>(std::count(folded.begin(), folded.end(), 1));
  std::vector<char> region(n, 0);
  for (int round = 0; round < kRounds && left > 0; ++round) {
    // The corners of the folded triangles and, after a round that did not help, a ring more.
    std::vector<char> grown = region;
    for (Index v = 0; v < n; ++v) {
      if (!region[v]) continue;
      for (const Index j : around[v]) {
        for (int k = 0; k < 3; ++k) grown[faces(j, k)] = 1;
      }
    }
    for (Index j = 0; j < faces.rows(); ++j) {
      if (!folded[j]) continue;
      for (int k = 0; k < 3; ++k) grown[faces(j, k)] = 1;
    }
    region.swap(grown);
    std::vector<Index> rows;
    for (Index v = 0; v < n; ++v) {
      if (region[v] && ends.row(v).allFinite()) rows.push_back(v);
    }
    // Gauss-Seidel sweeps: each vertex from its neighbours' current ends, in the plane of the
    // surface under its fan (the normals the fold test uses: S2's under the fan's corners and
    // centroids; at a crease of S2 one face's normal would disagree with it).
    Points3 trial = ends;
    for (int sweep = 0; sweep < kSweeps; ++sweep) {
      for (const Index v : rows) {
        std::vector<Index> fan;  // the triangles around v with every corner found
        for (const Index j : around[v]) {
          bool found = true;
          for (int k = 0; k < 3; ++k) found = found && trial.row(faces(j, k)).allFinite();
          if (found) fan.push_back(j);
        }
        if (fan.empty()) continue;
        Points3 at(static_cast<Index>(4 * fan.size()), 3);
        for (std::size_t i = 0; i < fan.size(); ++i) {
          V3 centroid = V3::Zero();
          for (int k = 0; k < 3; ++k) {
            at.row(static_cast<Index>(4 * i + k)) = trial.row(faces(fan[i], k));
            centroid += trial.row(faces(fan[i], k)).transpose() / 3.0;
          }
          at.row(static_cast<Index>(4 * i + 3)) = centroid.transpose();
        }
        const IndexVector under = index2.closest_points(at).faces;
        V3 normal = V3::Zero();
        for (Index k = 0; k < under.size(); ++k) {
          const V3 a = corner(v2, f2, under[k], 0);
          const V3 m = (corner(v2, f2, under[k], 1) - a).cross(corner(v2, f2, under[k], 2) - a);
          if (m.norm() > 0) normal += m.normalized();
        }
        if (!(normal.norm() > 0)) continue;
        const V3 end = into_kernel(v, fan, faces, trial, normal.normalized());
        if (!end.allFinite()) continue;
        const Points3 one = end.transpose();
        trial.row(v) = index2.closest_points(one).points.row(0);
      }
    }
    std::vector<char> trial_folded = test.folded(trial);
    descend(test, trial, trial_folded, faces, around, index2);
    const Index trial_left = static_cast<Index>(std::count(trial_folded.begin(), trial_folded.end(), 1));
    if (trial_left < left) {
      ends.swap(trial);
      folded.swap(trial_folded);
      left = trial_left;
    }
  }
  return left;
}

}  // namespace morphomap::detail
