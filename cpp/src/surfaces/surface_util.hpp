#pragma once
// Small double-precision triangle helpers and input checks shared by the surface kernels.
#include <morphomap/types.hpp>

#include <Eigen/Core>
#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>

#include <string>

namespace morphomap::detail {

using V3 = Eigen::Vector3d;

// Every coordinate finite, else InvalidInput "name: row i has a non-finite coordinate".
void require_finite3(const Points3Ref& points, const char* name);

// Every index in [0, vertex_count), else InvalidInput naming `name`.
void require_face_indices(const FacesRef& faces, Index vertex_count, const char* name);

inline V3 corner(const Points3Ref& v, const FacesRef& f, Index face, int k) { return v.row(f(face, k)).transpose(); }

// The area of a triangle surface: the sum of its faces' areas.
inline double surface_area(const Points3Ref& v, const FacesRef& f) {
  double area = 0.0;
  for (Index j = 0; j < f.rows(); ++j) {
    const V3 a = corner(v, f, j, 0);
    area += 0.5 * (corner(v, f, j, 1) - a).cross(corner(v, f, j, 2) - a).norm();
  }
  return area;
}

// area(S2) / area(S1): the factor alpha of the 3D quality measure's QM1, against which each
// triangle's change of area is measured (quality3d.cpp) and to which even_ends holds it.
inline double area_factor(const Points3Ref& v1, const FacesRef& f1, const Points3Ref& v2, const FacesRef& f2) {
  return surface_area(v2, f2) / surface_area(v1, f1);
}

// Unit normal of face `face` of (v, f), by its corners' order; zero where it has no area.
inline V3 unit_face_normal(const Points3Ref& v, const FacesRef& f, Index face) {
  const V3 a = corner(v, f, face, 0);
  const V3 n = (corner(v, f, face, 1) - a).cross(corner(v, f, face, 2) - a);
  const double length = n.norm();
  return length > 0 ? V3(n / length) : V3::Zero();
}

// unit_face_normal of every face of (v, f), one row each.
inline Points3 unit_face_normals(const Points3Ref& v, const FacesRef& f) {
  Points3 normals(f.rows(), 3);
  for (Index face = 0; face < f.rows(); ++face) normals.row(face) = unit_face_normal(v, f, face).transpose();
  return normals;
}

// Two unit vectors spanning the plane normal to the unit vector n, in order round it (t1 x t2 = n).
inline Eigen::Matrix<double, 3, 2> tangent_frame(const V3& n) {
  const V3 seed = std::abs(n.x()) < 0.9 ? V3::UnitX() : V3::UnitY();
  const V3 t1 = n.cross(seed).normalized();
  Eigen::Matrix<double, 3, 2> t;
  t.col(0) = t1;
  t.col(1) = n.cross(t1);
  return t;
}

// Barycentric coordinates of x (on or near the plane of triangle abc) in it; (1, 0, 0) where the
// triangle has no area.
inline V3 barycentric(const V3& a, const V3& b, const V3& c, const V3& x) {
  const V3 e1 = b - a, e2 = c - a, d = x - a;
  const double g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2), r1 = d.dot(e1), r2 = d.dot(e2);
  const double det = g11 * g22 - g12 * g12;
  if (!(det > 0.0)) return V3(1.0, 0.0, 0.0);
  const double l1 = (g22 * r1 - g12 * r2) / det, l2 = (g11 * r2 - g12 * r1) / det;
  return V3(1.0 - l1 - l2, l1, l2);
}

// Closest point to p on triangle abc (Ericson, "Real-Time Collision Detection" 5.1.5: walk the
// Voronoi regions of the vertices, edges and face); exact for degenerate triangles too.
inline V3 closest_on_triangle(const V3& p, const V3& a, const V3& b, const V3& c) {
  const V3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const V3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + (d1 / (d1 - d3)) * ab;
  const V3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + (d2 / (d2 - d6)) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);
  const double sum = va + vb + vc;
  if (!(sum > 0)) {  // degenerate (collinear) triangle: the nearest of its three edges
    V3 best = a;
    double best_d2 = (p - a).squaredNorm();
    const V3* ends[3][2] = {{&a, &b}, {&b, &c}, {&c, &a}};
    for (auto& e : ends) {
      const V3 d = *e[1] - *e[0];
      const double len2 = d.squaredNorm();
      const double t = len2 > 0 ? std::min(std::max((p - *e[0]).dot(d) / len2, 0.0), 1.0) : 0.0;
      const V3 q = *e[0] + t * d;
      if ((p - q).squaredNorm() < best_d2) best_d2 = (p - q).squaredNorm(), best = q;
    }
    return best;
  }
  const double v = vb / sum, w = vc / sum;
  return a + v * ab + w * ac;
}

// Intersection of the line o + t u with triangle abc (Moller-Trumbore in double precision);
// barycentric coordinates may be outside [0, 1] by `slack`. False for a line parallel to the
// triangle's plane.
inline bool line_triangle(const V3& o, const V3& u, const V3& a, const V3& b, const V3& c, double slack, double& t,
                          double& outside) {
  const V3 e1 = b - a, e2 = c - a;
  const V3 pvec = u.cross(e2);
  const double det = e1.dot(pvec);
  if (det == 0.0 || !std::isfinite(det)) return false;
  const double inv = 1.0 / det;
  const V3 s = o - a;
  const double bu = s.dot(pvec) * inv;
  const V3 qvec = s.cross(e1);
  const double bv = u.dot(qvec) * inv;
  outside = std::max({-bu, -bv, bu + bv - 1.0, 0.0});
  if (outside > slack) return false;
  t = e2.dot(qvec) * inv;
  return std::isfinite(t);
}

}  // namespace morphomap::detail
