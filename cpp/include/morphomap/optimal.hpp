#pragma once
// The order-preserving optimal matching of a piece of one curve onto a piece of another (the
// basic algorithm of method "optimal"): a monotone path through the grid of start points x target
// samples, found by dynamic programming.
#include <morphomap/types.hpp>

#include <vector>

namespace morphomap {

// The default weight of the stretch term (bench/README.md: QM on the bundled pairs for weights
// 0 to 1000; from about 10 on QM1 is below every row of the paper's Table 1 and gains little more).
constexpr double kDefaultStretchWeight = 10.0;

struct MonotoneMatch {
  Vector arcs;          // arc position of each end along the target, strictly increasing
  Points2 points;       // the end points on the target
  double energy = 0.0;  // the minimised energy (below)
  Index samples = 0;    // M: the target was sampled at M + 1 equally spaced positions
  // Every vector lies inside the region between the pieces, so none crosses another (below);
  // false: the penalised matching, checked to have no crossings.
  bool by_construction = false;
};

// Matches the start points source.row(start_rows[i]) (rows increasing) of the open polyline
// `source` onto the open polyline `target`, in order: the first and last rows of source and target
// are the ends of the pieces and correspond (virtual vectors source.row(0) -> target.row(0) and
// source.row(last) -> target.row(last); a start point that is row 0 or the last row is pinned to
// the target's end). Ends are chosen among M + 1 equally spaced target positions t_k = k L / M,
// M = max(4 (n + 1), min(target vertices, 8 (n + 1))), strictly increasing, minimising
//
//   E = sum_i |p_i - q_i|^2 / g^2  +  w * sum_pairs (L_j / (alpha l_j) - 1)^2
//
// over the n + 1 consecutive pairs (the virtual ends included; a pair with l_j = 0 adds nothing):
// l_j, L_j the arc lengths between consecutive starts / ends, alpha = target length / source
// length (so that the uniform map has no stretch), g^2 the mean squared distance from the starts
// to the target (at least the squared mean spacing of the starts, so that touching pieces stay
// well posed), w = stretch_weight (the paper's QM1 term; 0: nearest monotone matching). A step
// whose new vector crosses or touches (other than at a shared end) one of the three vectors before
// it costs 1e6 more, so the path avoids crossings where it can: exactly for the neighbour, for the
// two before that as the best path into the previous state has them (the state holds one vector;
// staircase contours of masks cross two or three apart). Vectors further apart are not checked. Each step advances by 1
// .. 8 M / (n + 1) + 2 samples.
//
// What is guaranteed, and what is not:
// - By construction: the order. Ends strictly increase along the target (bijective at the
//   sampling), the pieces' ends are pinned, so every stretch of the target lies between two ends.
// - Crossings: a step that crosses one of the three vectors checked is taken only where every
//   path avoiding it costs 1e6 more (the penalty is added, not forbidden). Vectors four or more
//   apart are not checked. A sufficient condition that rules every crossing out: each vector lies
//   inside the region bounded by the two pieces (they meet only at their ends, so it is a simple
//   polygon; whole closed curves: the ring between them cut along the first vector), since two chords of a simple
//   polygon whose ends do not interleave along its boundary cannot cross, and an order-preserving matching's ends never
//   interleave (start i, start j, end j, end i follow each other round the boundary). Vectors that leave the region
//   (round a bend of either curve) are not covered by it, so no crossing-free result is
//   promised: measured 0 on the bundled pairs, the shared frames and 60 fuzz pairs
//   (bench/README.md).
//
// Cost: coarse to fine. The starts are thinned by 4 per level down to <= 256, where the DP runs on
// the full grid; each finer level searches only a band of +- max(16, 8 M / (n + 1)) samples around
// the coarser path carried over by arc length (widened if the band admits no path). About
// n * band * step transitions per level: linear in n.
// InvalidInput naming "source", "start_rows", "target" or "stretch_weight" for bad input.
MonotoneMatch monotone_match(const Points2Ref& source, const std::vector<Index>& start_rows, const Points2Ref& target,
                             double stretch_weight = kDefaultStretchWeight);

}  // namespace morphomap
