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

// Over consecutive valid vectors (i, i+1) in field order, wrapping round on closed curves:
// l_i and L_i are the arc lengths between the start points on C1 and between the end points on
// C2 (the shorter way round on a closed curve), alpha = perimeter(C2) / perimeter(C1), A_i the
// area of the polygon bounded by the C1 arc, vector i+1, the C2 arc and vector i (absolute
// shoelace area). crossings: count_crossings of the vectors.
CurveQuality quality(const DisplacementField2& field, const Points2Ref& c1, const Points2Ref& c2,
                     bool closed = true);

}  // namespace morphomap
