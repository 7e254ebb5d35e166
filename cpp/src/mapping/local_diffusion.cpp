// The normal field where it is sound, diffusion near where it is not. Diffusion's streamlines
// depend on the whole region, but the part of it far from the failed vertices only needs to be
// meshed coarsely for their streamlines to stay as they are (bench/README.md, "A new bud, locally"),
// so the cost follows the part of S1 that is redone, not the whole surface.
#include "mapping/local_diffusion.hpp"

#include "common/nearest_point.hpp"
#include "quality/folds.hpp"
#include "surfaces/surface_util.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <vector>

namespace morphomap::detail {

namespace {

// In mean gaps between the surfaces: diffusion's ends are kept within kInner of a failed vertex
// (one whose normal misses or that a folded triangle has as a corner), then blended into the
// normal ends over kBand. A hard seam folded where the two fields differ by more than an edge
// (the bud pair of 20k faces: 93-170 folds with seams at 0.5-2 gaps; blended over a gap, none).
constexpr double kInner = 1.0;
constexpr double kBand = 1.0;
// Redoing more of S1 than this share costs about as much as diffusion over the whole surface.
constexpr double kMostShare = 0.5;
// Points along a normal that the mesh stays fine around: one a gap, at most this many (a normal
// many gaps long only spaces them further).
constexpr double kMostSteps = 64.0;

}  // namespace

std::optional<DisplacementField3> normal_with_local_diffusion(const DisplacementField3& normal,
                                                              const std::vector<char>& folded, const ShellPair& pair,
                                                              const SurfaceIndex& source_index,
                                                              const ShellDiffusionOptions& options) {
  const Index n = normal.size();
  std::vector<char> failed(static_cast<std::size_t>(n), 0);
  for (Index i = 0; i < n; ++i) failed[static_cast<std::size_t>(i)] = !normal.valid(i);
  for (Index f = 0; f < normal.faces.rows(); ++f) {
    if (!folded[static_cast<std::size_t>(f)]) continue;
    for (int k = 0; k < 3; ++k) failed[static_cast<std::size_t>(normal.faces(f, k))] = 1;
  }
  std::vector<std::array<double, 3>> seeds;
  for (Index i = 0; i < n; ++i) {
    if (failed[static_cast<std::size_t>(i)])
      seeds.push_back({normal.starts(i, 0), normal.starts(i, 1), normal.starts(i, 2)});
  }
  if (seeds.empty()) return std::nullopt;

  const double gap = std::abs(pair.target_volume - pair.source_volume) /
                     (0.5 * (surface_area(pair.source_vertices, pair.source_faces) +
                             surface_area(pair.target_vertices, pair.target_faces)));
  if (!(gap > 0.0) || !std::isfinite(gap)) return std::nullopt;
  const double inner = kInner * gap, outer = (kInner + kBand) * gap;
  const NearestPoint nearest(std::move(seeds));
  std::vector<double> distance(static_cast<std::size_t>(n));
  LocalDiffusion local;
  local.traced.assign(static_cast<std::size_t>(n), 0);
  std::vector<Index> redone;
  for (Index i = 0; i < n; ++i) {
    const std::size_t k = static_cast<std::size_t>(i);
    distance[k] = nearest.distance(normal.starts(i, 0), normal.starts(i, 1), normal.starts(i, 2));
    if (distance[k] < outer) {
      local.traced[k] = 1;
      redone.push_back(i);
    }
  }
  if (static_cast<double>(redone.size()) > kMostShare * static_cast<double>(n)) return std::nullopt;

  // The mesh stays fine to a gap around the redone vertices and along their normals to their
  // normal ends (about where their streamlines run).
  std::vector<Eigen::RowVector3d> focus;
  for (const Index i : redone) {
    focus.push_back(normal.starts.row(i));
    if (!normal.valid(i)) continue;
    const Eigen::RowVector3d along = normal.ends.row(i) - normal.starts.row(i);
    const int steps = static_cast<int>(std::min(std::ceil(along.norm() / gap), kMostSteps));
    for (int k = 1; k <= steps; ++k) focus.push_back(normal.starts.row(i) + along * (static_cast<double>(k) / steps));
  }
  local.focus.resize(static_cast<Index>(focus.size()), 3);
  for (std::size_t k = 0; k < focus.size(); ++k) local.focus.row(static_cast<Index>(k)) = focus[k];
  local.radius = gap;
  const ShellDiffusionSolution solved = solve_diffusion_3d(pair, options, &local);

  DisplacementField3 field = normal;
  std::vector<Index> blended;
  for (const Index i : redone) {
    if (!solved.ends.row(i).allFinite()) return std::nullopt;
    field.methods[static_cast<std::size_t>(i)] = Method::diffusion;
    const double d = distance[static_cast<std::size_t>(i)];
    if (d <= inner || !normal.valid(i)) {
      field.ends.row(i) = solved.ends.row(i);
      continue;
    }
    const double w = (outer - d) / (outer - inner);
    field.ends.row(i) = w * solved.ends.row(i) + (1.0 - w) * normal.ends.row(i);
    blended.push_back(i);
  }
  if (!blended.empty()) {
    const Points3 onto = pair.target_index.closest_points(field.ends(blended, Eigen::all)).points;
    for (std::size_t k = 0; k < blended.size(); ++k) field.ends.row(blended[k]) = onto.row(static_cast<Index>(k));
  }
  const Points3 placed = field.ends;
  const Index left = unfold(field.starts, field.ends, field.faces, pair.source_vertices, pair.source_faces,
                            source_index, pair.target_vertices, pair.target_faces, pair.target_index);
  if (left > 0) return std::nullopt;
  for (Index i = 0; i < n; ++i) {
    if (!field.valid(i)) return std::nullopt;
  }
  // Touching vertices went to their closest point (as in diffusion mapping), unless moved since.
  for (const Index i : redone) {
    if (solved.touching[static_cast<std::size_t>(i)] && field.ends.row(i) == placed.row(i) &&
        field.ends.row(i) == solved.ends.row(i)) {
      field.methods[static_cast<std::size_t>(i)] = Method::minimal_distance;
    }
  }
  return field;
}

}  // namespace morphomap::detail
