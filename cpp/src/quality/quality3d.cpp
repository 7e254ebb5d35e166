// The quality measures of a 3D displacement field (ours; see quality.hpp for the formulas).
#include <morphomap/quality.hpp>
#include <morphomap/surface_queries.hpp>

#include "common/finite_rows.hpp"
#include "common/numbers.hpp"
#include "common/validation.hpp"
#include "quality/folds.hpp"
#include "surfaces/surface_util.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace morphomap {

using detail::kNaN;

namespace {

using detail::V3;

bool usable(const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces, Index j) {
  for (int k = 0; k < 3; ++k) {
    const Index i = faces(j, k);
    if (!starts.row(i).allFinite() || !ends.row(i).allFinite()) return false;
  }
  return true;
}

void require_field_faces(const FacesRef& faces, Index rows, const char* name) {
  for (Index j = 0; j < faces.rows(); ++j) {
    for (int k = 0; k < 3; ++k) {
      if (faces(j, k) < 0 || faces(j, k) >= rows) {
        detail::invalid(name, "face " + std::to_string(j) + " refers to row " + std::to_string(faces(j, k)) +
                                  ", outside 0.." + std::to_string(rows - 1));
      }
    }
  }
}

double surface_area(const Points3Ref& v, const FacesRef& f) {
  double area = 0.0;
  for (Index j = 0; j < f.rows(); ++j) {
    const V3 a = detail::corner(v, f, j, 0);
    area += 0.5 * (detail::corner(v, f, j, 1) - a).cross(detail::corner(v, f, j, 2) - a).norm();
  }
  return area;
}

double tetrahedron(const V3& a, const V3& b, const V3& c, const V3& d) {
  return std::abs((b - a).dot((c - a).cross(d - a))) / 6.0;
}

// Every valid row of `points` within `tolerance` of the surface.
void require_on(const Points3Ref& points, const Points3Ref& v, const SurfaceIndex& index, const char* what) {
  const std::vector<Index> rows = detail::finite_rows(points);
  if (rows.empty()) return;
  const Points3 found = points(rows, Eigen::all);
  const double tolerance = 1e-6 * (v.colwise().maxCoeff() - v.colwise().minCoeff()).norm();
  const Vector d = index.closest_points(found).distances;
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (!(d[k] <= tolerance)) {
      detail::invalid("field", std::string(what) + " " + std::to_string(rows[k]) + " is " + std::to_string(d[k]) +
                                   " away from the surface it should lie on");
    }
  }
}

// Unit normal of face `face` of (v, f); InvalidInput naming `name` when the index that found it
// was not built from this surface.
V3 unit_face_normal(const Points3Ref& v, const FacesRef& f, Index face, const char* name) {
  if (face < 0 || face >= f.rows()) detail::invalid(name, "the surface index does not match its faces");
  const V3 a = detail::corner(v, f, face, 0);
  const V3 n = (detail::corner(v, f, face, 1) - a).cross(detail::corner(v, f, face, 2) - a);
  const double length = n.norm();
  return length > 0 ? V3(n / length) : V3::Zero();
}

// For each triangle of `faces` over the rows of `points` (only where `use`), the sum nu of the unit
// normals of the surface's faces closest to its three corners and to its centroid. The corners lie
// on the surface, so their faces give the normal right there, even when the triangle is large
// against the surface's curvature (across a thin tube its centroid sinks towards the axis); but a
// corner on a vertex or edge of the surface gets any of the faces meeting there, while the
// centroid of a small triangle lies over the face it covers. Together they outvote either failure.
Points3 normals_under(const Points3Ref& points, const FacesRef& faces, const std::vector<char>& use,
                      const Points3Ref& v, const FacesRef& f, const SurfaceIndex& index, const char* name) {
  const std::vector<Index> rows = detail::finite_rows(points);
  Points3 at_rows = Points3::Zero(points.rows(), 3);
  Points3 nu = Points3::Zero(faces.rows(), 3);
  if (rows.empty()) return nu;
  {
    const Points3 queries = points(rows, Eigen::all);
    const IndexVector hit = index.closest_points(queries).faces;
    for (std::size_t k = 0; k < rows.size(); ++k)
      at_rows.row(rows[k]) = unit_face_normal(v, f, hit[k], name).transpose();
  }
  std::vector<Index> triangles;
  for (Index j = 0; j < faces.rows(); ++j) {
    if (use[j]) triangles.push_back(j);
  }
  if (triangles.empty()) return nu;
  Points3 centroids(triangles.size(), 3);
  for (std::size_t k = 0; k < triangles.size(); ++k) {
    const Index j = triangles[k];
    centroids.row(k) = (points.row(faces(j, 0)) + points.row(faces(j, 1)) + points.row(faces(j, 2))) / 3.0;
  }
  const IndexVector hit = index.closest_points(centroids).faces;
  for (std::size_t k = 0; k < triangles.size(); ++k) {
    const Index j = triangles[k];
    nu.row(j) = unit_face_normal(v, f, hit[k], name).transpose() + at_rows.row(faces(j, 0)) + at_rows.row(faces(j, 1)) +
                at_rows.row(faces(j, 2));
  }
  return nu;
}

}  // namespace

std::vector<char> detail::folded_faces(const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces,
                                       const Points3Ref& v1, const FacesRef& f1, const SurfaceIndex& index1,
                                       const Points3Ref& v2, const FacesRef& f2, const SurfaceIndex& index2) {
  if (ends.rows() != starts.rows()) detail::invalid("ends", "must have as many rows as starts");
  require_field_faces(faces, starts.rows(), "faces");
  std::vector<char> use(faces.rows());
  for (Index j = 0; j < faces.rows(); ++j) use[j] = usable(starts, ends, faces, j);
  const Points3 nu1 = normals_under(starts, faces, use, v1, f1, index1, "s1");
  const Points3 nu2 = normals_under(ends, faces, use, v2, f2, index2, "s2");
  std::vector<char> folded(faces.rows(), 0);
  tbb::parallel_for(tbb::blocked_range<Index>(0, faces.rows(), 1024), [&](const tbb::blocked_range<Index>& range) {
    for (Index j = range.begin(); j < range.end(); ++j) {
      if (!use[j]) continue;
      const V3 p0 = detail::corner(starts, faces, j, 0), q0 = detail::corner(ends, faces, j, 0);
      const V3 n = (detail::corner(starts, faces, j, 1) - p0).cross(detail::corner(starts, faces, j, 2) - p0);
      const V3 m = (detail::corner(ends, faces, j, 1) - q0).cross(detail::corner(ends, faces, j, 2) - q0);
      // Signs only: the product of two dot products of unscaled vectors could underflow.
      const double on1 = n.dot(nu1.row(j).transpose()), on2 = m.dot(nu2.row(j).transpose());
      folded[j] = (on1 < 0 && on2 > 0) || (on1 > 0 && on2 < 0);
    }
  });
  return folded;
}

Index count_folds(const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces, const Points3Ref& v1,
                  const FacesRef& f1, const SurfaceIndex& index1, const Points3Ref& v2, const FacesRef& f2,
                  const SurfaceIndex& index2) {
  const std::vector<char> folded = detail::folded_faces(starts, ends, faces, v1, f1, index1, v2, f2, index2);
  return static_cast<Index>(std::count(folded.begin(), folded.end(), 1));
}

Index count_folds(const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces, const Points3Ref& v1,
                  const FacesRef& f1, const Points3Ref& v2, const FacesRef& f2) {
  detail::require_outward(check_closed_surface(v1, f1, "s1"), "s1");
  detail::require_outward(check_closed_surface(v2, f2, "s2"), "s2");
  return count_folds(starts, ends, faces, v1, f1, SurfaceIndex(v1, f1), v2, f2, SurfaceIndex(v2, f2));
}

namespace {

// quality on two checked surfaces, queried through their indexes.
SurfaceQuality checked_quality(const DisplacementField3& field, const Points3Ref& v1, const FacesRef& f1,
                               const SurfaceIndex& index1, const Points3Ref& v2, const FacesRef& f2,
                               const SurfaceIndex& index2) {
  if (field.ends.rows() != field.starts.rows() || field.starts.cols() != 3 || field.ends.cols() != 3) {
    detail::invalid("field", "starts and ends must both have shape (M, 3)");
  }
  require_field_faces(field.faces, field.size(), "field");
  require_on(field.starts, v1, index1, "start point");
  require_on(field.ends, v2, index2, "end point");

  const double alpha = surface_area(v2, f2) / surface_area(v1, f1);
  const Index count = field.faces.rows();
  std::vector<double> ratio(count, kNaN), volume(count, kNaN);
  for (Index j = 0; j < count; ++j) {
    if (!usable(field.starts, field.ends, field.faces, j)) continue;
    const V3 p0 = detail::corner(field.starts, field.faces, j, 0), p1 = detail::corner(field.starts, field.faces, j, 1),
             p2 = detail::corner(field.starts, field.faces, j, 2);
    const V3 q0 = detail::corner(field.ends, field.faces, j, 0), q1 = detail::corner(field.ends, field.faces, j, 1),
             q2 = detail::corner(field.ends, field.faces, j, 2);
    const double a = 0.5 * (p1 - p0).cross(p2 - p0).norm();
    const double image = 0.5 * (q1 - q0).cross(q2 - q0).norm();
    if (a > 0) ratio[j] = image / (alpha * a);
    volume[j] = tetrahedron(p0, p1, p2, q0) + tetrahedron(p1, p2, q0, q1) + tetrahedron(p2, q0, q1, q2);
  }
  SurfaceQuality q;
  double sum1 = 0.0, sum_v = 0.0;
  Index k1 = 0, k = 0;
  for (Index j = 0; j < count; ++j) {
    if (std::isfinite(ratio[j])) sum1 += (ratio[j] - 1.0) * (ratio[j] - 1.0), ++k1;
    if (std::isfinite(volume[j])) sum_v += volume[j], ++k;
  }
  q.qm1 = k1 > 0 ? sum1 / k1 : kNaN;
  const double mean_v = k > 0 ? sum_v / k : kNaN;
  if (k > 0 && mean_v > 0) {
    double sum2 = 0.0;
    for (Index j = 0; j < count; ++j) {
      if (std::isfinite(volume[j])) sum2 += (volume[j] / mean_v - 1.0) * (volume[j] / mean_v - 1.0);
    }
    q.qm2 = sum2 / k;
  } else {
    q.qm2 = kNaN;
  }
  q.qm = q.qm1 * q.qm2;
  q.folds = count_folds(field.starts, field.ends, field.faces, v1, f1, index1, v2, f2, index2);
  return q;
}

}  // namespace

SurfaceQuality quality(const DisplacementField3& field, const Points3Ref& v1, const FacesRef& f1, const Points3Ref& v2,
                       const FacesRef& f2) {
  detail::require_outward(check_closed_surface(v1, f1, "s1"), "s1");
  detail::require_outward(check_closed_surface(v2, f2, "s2"), "s2");
  return checked_quality(field, v1, f1, SurfaceIndex(v1, f1), v2, f2, SurfaceIndex(v2, f2));
}

SurfaceQuality quality(const DisplacementField3& field, const PreparedSurface& s1, const PreparedSurface& s2) {
  return checked_quality(field, s1.vertices(), s1.faces(), s1.index(), s2.vertices(), s2.faces(), s2.index());
}

}  // namespace morphomap
