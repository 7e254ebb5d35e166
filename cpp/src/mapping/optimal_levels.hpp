#pragma once
// Method "optimal"'s dynamic programming over its levels, coarse to fine (optimal_levels.cpp), and
// the problem it solves, which monotone_match sets up (optimal.cpp).
#include <morphomap/optimal.hpp>

#include "curves/arc_curve.hpp"
#include "mapping/match_region.hpp"

#include <vector>

namespace morphomap::detail {

// Matchings of at most this many starts (outlines as traced, ~200 points) are worth more search:
// each finer level's band reaches 8 starts' worth of samples beyond the coarse path (2 above), and
// a path through a forced jump is compared with the one found without the region.
constexpr Index kSmallMatch = 256;

// The problem of one call: start points with their arc positions, the two pieces' lengths, the
// virtual vectors at both ends, and the weights.
struct MatchProblem {
  Points2 starts;
  Vector s;  // arc position of each start along the source
  double source_length = 0.0, target_length = 0.0;
  Vec2 begin_source, begin_target, end_source, end_target;
  bool pinned_first = false, pinned_last = false;
  double displacement_weight = 1.0;  // 1 / g^2
  double stretch_weight = kDefaultStretchWeight;
  double alpha = 1.0;
  const ArcCurve* target = nullptr;
  std::vector<double> vertex_arcs;      // arc position of each vertex of the target
  bool uneven_target = false;           // an edge longer than kUneven (optimal.cpp) times the median
  const MatchRegion* region = nullptr;  // the hard constraint, where the region is a polygon
};

// All levels, coarse to fine (levels.front() the finest, all the starts; each coarser one a subset
// of the one below), into the target positions of the starts (coarse_t) and the energy. With
// p.region the finest level takes only vectors inside the region, its band widened a few times
// (false when that finds no path); a coarser level that finds none there is solved without it (it
// only centres the next band). Without the region a band is widened until a path exists.
// `jumped` is set where a level's path took a forced jump. finest: the finest level's samples.
bool solve_levels(const MatchProblem& p, const std::vector<std::vector<Index>>& levels, Index finest,
                  const std::vector<Index>& start_rows, std::vector<double>& coarse_t, double& energy, bool& jumped);

}  // namespace morphomap::detail
