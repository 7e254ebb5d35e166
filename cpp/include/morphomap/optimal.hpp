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
  Vector arcs;          // arc position of each end along the target, increasing (below)
  Points2 points;       // the end points on the target
  double energy = 0.0;  // the minimised energy (below)
  Index samples = 0;    // M: the finest level's equally spaced samples number M + 1 (below)
  // Every vector lies inside the region between the pieces, a simple polygon, so none can cross
  // another (below); false: a matching found otherwise, counted to have no crossings.
  bool by_construction = false;
};

// Matches the start points source.row(start_rows[i]) (rows increasing) of the open polyline
// `source` onto the open polyline `target`, in order: the first and last rows of source and target
// are the ends of the pieces and correspond (virtual vectors source.row(0) -> target.row(0) and
// source.row(last) -> target.row(last); a start point that is row 0 or the last row is pinned to
// the target's end). Ends are chosen among M + 1 equally spaced target positions t_k = k L / M,
// M = max(4 (n + 1), min(target vertices, 8 (n + 1))), joined by the uniform map's position
// alpha s_i of each start (on a target with an edge over 4 times its median, half of the M + 1
// spaced evenly along it and half evenly through its vertices); strictly increasing, minimising
//
//   E = sum_i |p_i - q_i|^2 / g^2  +  w * sum_pairs (L_j / (alpha l_j) - 1)^2
//
// over the n + 1 consecutive pairs (the virtual ends included; a pair with l_j = 0 adds nothing):
// l_j, L_j the arc lengths between consecutive starts / ends, alpha = target length / source
// length (so that the uniform map has no stretch), g^2 the mean squared distance from the starts
// to the target (at least the squared mean spacing of the starts, so that touching pieces stay
// well posed), w = stretch_weight (the paper's QM1 term; 0: nearest monotone matching).
// Each step advances by 1 .. 8 M' / (n + 1) + 2 samples (M' + 1 of them in all).
//
// The region, a hard constraint: the pieces and the two end vectors bound a region (whole closed
// curves: the ring between them cut along the first vector). A vector p_i -> q_k may be taken only
// if it lies inside that region: no point of the region's boundary strictly between its ends (one
// line query from its midpoint, up to 1e-9 of its length), and it leaves both curves into the
// region (exact orientation tests at both ends, so that a vector along a curve or out of the region
// is refused). A vector of length 0 (the curves touching there) is taken.
//
// What is guaranteed, and when:
// - Always: the order. Ends strictly increase along the target (bijective at the sampling), the
//   pieces' ends are pinned, so every stretch of the target lies between two ends. One exception:
//   where the source doubles back next to a pinned end or an end vector (a traced tip whose last
//   point lies back across the one before), every strictly increasing path crosses that vector;
//   the free rows between it and a row crossing it then share its end point, if that leaves fewer
//   crossings (never among free rows alone).
// - No two vectors of the result cross (crossing_pairs: no common point but a shared end), nor
//   cross the end vectors:
//   * by construction (by_construction) where the region is the inside of a simple polygon (the
//     pieces meet only at their ends, the end vectors cross nothing; checked exactly) or, whole
//     closed curves, the ring between two disjoint nested simple curves cut along a first vector
//     that meets them only at its ends, and a path of vectors inside it exists at the sampling
//     (the band widened at most twice). Two straight segments inside a simple polygon whose ends
//     lie on its boundary without interleaving cannot cross (one would separate the other's ends),
//     and a monotone matching's ends never interleave: start i, start j, end j, end i follow each
//     other round the boundary;
//   * otherwise, as checked: the path of vectors inside the region (where it is not simple), else
//     the penalised path (a step whose vector crosses or touches one of the three before it on the
//     path costs 1e6 more), is returned only if an exact count (count_crossings, the end vectors
//     included) finds no crossing; else GeometryError ("no crossing-free order-preserving
//     matching"), never a field with crossings. (Every result is counted so, the ones by
//     construction too: their inside test rounds at 1e-9 of a vector's length.)
// - Between pieces (method "optimal" maps each pair of pieces between split points on its own):
//   vectors of two pieces cannot cross where the pieces' regions do not overlap, as for curves
//   that cross in the same order along both.
//
// Cost: coarse to fine. The starts are thinned by 4 per level down to <= 256, where the DP runs on
// the full grid; each finer level searches only a band of +- max(16, 8 M / (n + 1)) samples around
// the coarser path carried over by arc length (widened if the band admits no path). About
// n * band * step transitions per level and one line query per cell of the band: linear in n
// (bench/README.md: 10^4 points per curve in under a second on 2 cores).
// InvalidInput naming "source", "start_rows", "target" or "stretch_weight" for bad input;
// GeometryError where no crossing-free matching was found (above).
MonotoneMatch monotone_match(const Points2Ref& source, const std::vector<Index>& start_rows, const Points2Ref& target,
                             double stretch_weight = kDefaultStretchWeight);

}  // namespace morphomap
