#pragma once
// The paper's quality measures of a 2D displacement field (section "Quantitative Evaluation").
#include <morphomap/field.hpp>
#include <morphomap/types.hpp>

namespace morphomap {

struct CurveQuality {
  double qm1 = 0.0;    // < (L_i / (alpha l_i) - 1)^2 >
  double qm2 = 0.0;    // < (A_i / <A> - 1)^2 >
  double qm = 0.0;     // qm1 * qm2
  Index crossings = 0; // pairs of vectors whose segments cross
};

// Quality of the vectors p_i -> P_i (p_i = field.starts[i] on c1, P_i = field.ends[i] on c2).
//
// Pairs: consecutive vectors (i, i+1) in field order, i = 0 .. M-2, plus (M-1, 0) when closed;
// a pair involving an invalid (NaN) row is skipped. Over the remaining K pairs:
//   l_i   = arc length on c1 between p_i and p_{i+1}, L_i = the same on c2 between P_i and
//           P_{i+1}; on a closed curve the shorter way round (forward at an exact tie).
//   alpha = perimeter(c2) / perimeter(c1) (the lengths of the open curves when not closed).
//   QM1   = (1/K1) sum_i (L_i / (alpha l_i) - 1)^2 over the K1 pairs with l_i > 0: a pair with
//           coincident start points (l_i == 0) has no ratio and is left out of QM1 only.
//   A_i   = |shoelace area| of the polygon p_i, the vertices of c1 strictly between p_i and
//           p_{i+1} along the arc that gave l_i, p_{i+1}, P_{i+1}, the vertices of c2 strictly
//           between P_{i+1} and P_i along the arc that gave L_i, P_i (closing back to p_i).
//   <A>   = (1/K) sum_i A_i,  QM2 = (1/K) sum_i (A_i / <A> - 1)^2.
//   QM    = QM1 * QM2.
// A measure is NaN when it has nothing to average over (no pair, or <A> == 0).
// crossings = count_crossings(field.starts, field.ends).
//
// Every valid start point must lie on c1 and every valid end point on c2 (within 1e-6 of the
// curve's bounding-box diagonal), else InvalidInput naming "field". Curves as in require_curve.
// Cost: a bounding-volume hierarchy per curve to find the arc position of each point, then
// O(M + vertices walked) in parallel; each area walks only the vertices between two points.
CurveQuality quality(const DisplacementField2& field, const Points2Ref& c1, const Points2Ref& c2,
                     bool closed = true);

}  // namespace morphomap
