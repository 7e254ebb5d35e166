#pragma once
// The paper's quality measures of a 2D displacement field (section "Quantitative Evaluation").
#include <morphomap/field.hpp>
#include <morphomap/prepared_curve.hpp>
#include <morphomap/prepared_surface.hpp>
#include <morphomap/surface_queries.hpp>
#include <morphomap/types.hpp>

namespace morphomap {

struct CurveQuality {
  double qm1 = 0.0;     // < (L_i / (alpha l_i) - 1)^2 >
  double qm2 = 0.0;     // < (A_i / <A> - 1)^2 >
  double qm = 0.0;      // qm1 * qm2
  Index crossings = 0;  // pairs of vectors whose segments cross
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
CurveQuality quality(const DisplacementField2& field, const Points2Ref& c1, const Points2Ref& c2, bool closed = true);
// The same on curves checked and indexed once (their indices are reused), bit for bit; both must
// have been prepared as `closed` asks (InvalidInput naming "c1" or "c2" otherwise).
CurveQuality quality(const DisplacementField2& field, const PreparedCurve& c1, const PreparedCurve& c2,
                     bool closed = true);

}  // namespace morphomap

// ---- 3D ---------------------------------------------------------------------------------------
namespace morphomap {

struct SurfaceQuality {
  double qm1 = 0.0;  // < (A_j / (alpha a_j) - 1)^2 >
  double qm2 = 0.0;  // < (V_j / <V> - 1)^2 >
  double qm = 0.0;   // qm1 * qm2
  Index folds = 0;   // triangles whose image is turned over
};

// Number of triangles j of `faces` (rows of starts/ends) whose image is turned over relative to
// the surfaces, i.e. where the map from S1 to S2 reverses orientation:
//   n_j  = (p1 - p0) x (p2 - p0) of the start points, N_j the same of the end points (corners in
//          the order of the face row);
//   nu1_j = the sum of the unit normals of the faces of S1 closest to p0, p1, p2 and to the
//          centroid (p0 + p1 + p2) / 3; nu2_j the same on S2 for P0, P1, P2;
//   fold  when (n_j . nu1_j) * (N_j . nu2_j) < 0.
// A triangle lying on its surface as that surface is oriented has n . nu > 0: a start triangle
// that is a face of S1 counts when its image faces into S2, and, for the faces of S2 mapped back
// (reverse fields), an image that is a face of S2 counts when its start triangle faces into S1.
// Tilt in space does not count, so a smooth deformation (a bud that grows out sideways) gives none,
// nor does a translation, rotation or scaling; an image that is locally mirrored does. A triangle
// with a NaN row (a miss), or with a zero-area start or image, is not a fold.
// Both surfaces must be closed with outward faces (check_closed_surface, named "s1" and "s2");
// faces must index the rows of starts, else InvalidInput naming "faces".
Index count_folds(const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces, const Points3Ref& v1,
                  const FacesRef& f1, const Points3Ref& v2, const FacesRef& f2);

// The same with the surfaces' indices already built (index1 from v1, f1 and index2 from v2, f2),
// for callers that query the surfaces anyway; the surfaces are not checked again.
Index count_folds(const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces, const Points3Ref& v1,
                  const FacesRef& f1, const SurfaceIndex& index1, const Points3Ref& v2, const FacesRef& f2,
                  const SurfaceIndex& index2);

// Quality of a 3D field p_i -> P_i (our definitions; the paper gives none for 3D).
//
// Triangles: the rows of field.faces (indices into the field's rows); a triangle with an invalid
// (NaN) vector is skipped. Over the remaining K triangles j with corners p0, p1, p2 and images
// P0, P1, P2:
//   a_j   = |(p1 - p0) x (p2 - p0)| / 2, A_j = the same of P0, P1, P2.
//   alpha = area(S2) / area(S1) (sums of the triangle areas of the surfaces).
//   QM1   = (1/K1) sum_j (A_j / (alpha a_j) - 1)^2 over the K1 triangles with a_j > 0.
//   V_j   = the volume swept between the start triangle and its image: the solid with the two
//           triangles as caps and the three vector quads as sides, split into the tetrahedra
//           (p0 p1 p2 P0), (p1 p2 P0 P1), (p2 P0 P1 P2); V_j = sum of their absolute volumes.
//   <V>   = (1/K) sum_j V_j,  QM2 = (1/K) sum_j (V_j / <V> - 1)^2.
//   QM    = QM1 * QM2.
// A measure is NaN when it has nothing to average over (no triangle, or <V> == 0).
// folds = count_folds(field.starts, field.ends, field.faces, v1, f1, v2, f2).
//
// Both surfaces must pass check_closed_surface (named "s1", "s2"); every valid start point must
// lie on S1 and every valid end point on S2 within 1e-6 of the surface's bounding-box diagonal,
// and field.faces must index the field's rows, else InvalidInput naming "field".
SurfaceQuality quality(const DisplacementField3& field, const Points3Ref& v1, const FacesRef& f1, const Points3Ref& v2,
                       const FacesRef& f2);
// The same on surfaces checked and indexed once.
SurfaceQuality quality(const DisplacementField3& field, const PreparedSurface& s1, const PreparedSurface& s2);

}  // namespace morphomap
