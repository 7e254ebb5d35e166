#pragma once
// solve_diffusion without the curves' and options' checks, for map_curves, which checked its
// curves (require_simple_curve) and options (validate_options) at its entry and calls this on
// the whole pair and on pieces of it. The rules that are diffusion's own (coordinates in range,
// nested or crossing closed curves) still apply here.
#include <morphomap/laplace.hpp>

#include <algorithm>

namespace morphomap::detail {

// The lattice's vertex budget with an automatic mesh size (see DiffusionOptions::mesh_size): a
// pair of curves with `points` points in all gets max(40000, 20 * points).
inline double vertex_budget(Index points) { return std::max(4e4, 20.0 * static_cast<double>(points)); }

// The budget of one piece of a split pair: the pair's budget shared by the pieces' points, so
// that a pair split into many pieces costs about what it would whole, with at least 20 vertices
// per point and 2000 per piece (about 50 across a round lobe). 0 for the whole pair: its own.
inline double piece_vertex_budget(Index piece_points, Index pair_points) {
  if (piece_points >= pair_points) return 0.0;
  const double share = static_cast<double>(piece_points) / static_cast<double>(pair_points);
  return std::max({2000.0, share * vertex_budget(pair_points), 20.0 * static_cast<double>(piece_points)});
}

// The checks solve_diffusion makes of its curves: each simple, closed ones with area.
void require_diffusion_curves(const Points2Ref& source_points, const Points2Ref& target_points, bool closed);

// vertex_budget <= 0: the pair's own (vertex_budget of both curves' points).
DiffusionSolution solve_diffusion_unchecked(const Points2Ref& source_points, const Points2Ref& target_points,
                                            bool closed, const DiffusionOptions& options, double vertex_budget = 0.0);

}  // namespace morphomap::detail
