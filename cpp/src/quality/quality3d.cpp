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
#include <numeric>
#include <string>
#include <vector>

namespace morphomap {

using detail::kNaN;

namespace {

// A centroid this close to the surface, relative to its triangle's longest edge, lies on it:
// the rounding of the closest-point query, far below any chord's sagitta.
constexpr double kOnSurface = 1e-9;

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
  return detail::unit_face_normal(v, f, face);
}

// For each of `triangles` (rows of `faces` over `points`, every corner finite), the sum nu of the
// unit normals of the surface's faces closest to its three corners and to its centroid. The
// corners lie on the surface, so their faces give the normal right there, even when the triangle
// is large against the surface's curvature (across a thin tube its centroid sinks towards the
// axis); but a corner on a vertex or edge of the surface gets any of the faces meeting there, while
// the centroid of a small triangle lies over the face it covers. Together they outvote either
// failure, except where every corner lies on a sharp crease: a triangle lying on the surface
// takes the normal of the face under its centroid alone.
Points3 normals_under(const Points3Ref& points, const FacesRef& faces, const std::vector<Index>& triangles,
                      const Points3Ref& v, const FacesRef& f, const SurfaceIndex& index, const char* name) {
  const Index count = static_cast<Index>(triangles.size());
  Points3 nu = Points3::Zero(count, 3);
  if (count == 0) return nu;
  std::vector<Index> corners;  // the distinct corners, each queried once
  corners.reserve(3 * triangles.size());
  for (const Index j : triangles) {
    for (int k = 0; k < 3; ++k) corners.push_back(faces(j, k));
  }
  std::sort(corners.begin(), corners.end());
  corners.erase(std::unique(corners.begin(), corners.end()), corners.end());
  const IndexVector corner_hit = index.closest_points(points(corners, Eigen::all)).faces;
  auto at_corner = [&](Index row) {
    const auto k = std::lower_bound(corners.begin(), corners.end(), row) - corners.begin();
    return unit_face_normal(v, f, corner_hit[k], name);
  };
  Points3 centroids(count, 3);
  for (Index k = 0; k < count; ++k) {
    const Index j = triangles[static_cast<std::size_t>(k)];
    centroids.row(k) = (points.row(faces(j, 0)) + points.row(faces(j, 1)) + points.row(faces(j, 2))) / 3.0;
  }
  const SurfaceHits hit = index.closest_points(centroids);
  for (Index k = 0; k < count; ++k) {
    const Index j = triangles[static_cast<std::size_t>(k)];
    const V3 under = unit_face_normal(v, f, hit.faces[k], name);
    // A triangle whose centroid lies on the surface lies on it (it is one of its faces, or inside
    // a flat part): that face's normal is its orientation, and the corners' faces, which at a
    // sharp crease may all lie on the crease's other side, are not asked.
    const double size = std::max({(points.row(faces(j, 1)) - points.row(faces(j, 0))).norm(),
                                  (points.row(faces(j, 2)) - points.row(faces(j, 1))).norm(),
                                  (points.row(faces(j, 0)) - points.row(faces(j, 2))).norm()});
    if (hit.distances[k] <= kOnSurface * size) {
      nu.row(k) = under.transpose();
      continue;
    }
    nu.row(k) = (under + at_corner(faces(j, 0)) + at_corner(faces(j, 1)) + at_corner(faces(j, 2))).transpose();
  }
  return nu;
}

V3 triangle_normal(const Points3Ref& points, const FacesRef& faces, Index j) {
  const V3 a = detail::corner(points, faces, j, 0);
  return (detail::corner(points, faces, j, 1) - a).cross(detail::corner(points, faces, j, 2) - a);
}

}  // namespace

detail::FoldTest::FoldTest(const Points3Ref& starts, const FacesRef& faces, const Points3Ref& v1, const FacesRef& f1,
                           const SurfaceIndex& index1, const Points3Ref& v2, const FacesRef& f2,
                           const SurfaceIndex& index2)
    : starts_(starts), faces_(faces), v2_(v2), f2_(f2), index2_(index2), start_sign_(faces.rows(), 0) {
  require_field_faces(faces, starts.rows(), "faces");
  std::vector<Index> placed;  // the triangles with every start
  for (Index j = 0; j < faces.rows(); ++j) {
    if (usable(starts, starts, faces, j)) placed.push_back(j);
  }
  const Points3 nu1 = normals_under(starts, faces, placed, v1, f1, index1, "s1");
  for (std::size_t k = 0; k < placed.size(); ++k) {
    const double on1 = triangle_normal(starts, faces, placed[k]).dot(nu1.row(static_cast<Index>(k)).transpose());
    start_sign_[static_cast<std::size_t>(placed[k])] = static_cast<signed char>((on1 > 0) - (on1 < 0));
  }
}

std::vector<double> detail::FoldTest::agreement(const Points3Ref& ends, const std::vector<Index>& triangles) const {
  if (ends.rows() != starts_.rows()) detail::invalid("ends", "must have as many rows as starts");
  std::vector<double> out(triangles.size(), kNaN);
  std::vector<Index> placed;  // positions in `triangles` with every start and end
  for (std::size_t k = 0; k < triangles.size(); ++k) {
    if (usable(starts_, ends, faces_, triangles[k])) placed.push_back(static_cast<Index>(k));
  }
  std::vector<Index> rows(placed.size());
  for (std::size_t k = 0; k < placed.size(); ++k) rows[k] = triangles[static_cast<std::size_t>(placed[k])];
  const Points3 nu2 = normals_under(ends, faces_, rows, v2_, f2_, index2_, "s2");
  tbb::parallel_for(
      tbb::blocked_range<std::size_t>(0, rows.size(), 1024), [&](const tbb::blocked_range<std::size_t>& range) {
        for (std::size_t k = range.begin(); k < range.end(); ++k) {
          const V3 m = triangle_normal(ends, faces_, rows[k]);
          const V3 n = nu2.row(static_cast<Index>(k)).transpose();
          const double on2 = m.dot(n), scale = m.norm() * n.norm();
          // The sign decides (0 where the image or the normal under it is flat);
          // the cosine only ranks, and a tiny image whose norm underflows keeps its sign.
          const double cosine = scale > 0 ? on2 / scale : double((on2 > 0) - (on2 < 0));
          out[static_cast<std::size_t>(placed[k])] = start_sign_[static_cast<std::size_t>(rows[k])] * cosine;
        }
      });
  return out;
}

std::vector<char> detail::FoldTest::folded(const Points3Ref& ends) const {
  std::vector<Index> every(static_cast<std::size_t>(faces_.rows()));
  std::iota(every.begin(), every.end(), Index{0});
  const std::vector<double> a = agreement(ends, every);
  std::vector<char> out(a.size());
  for (std::size_t j = 0; j < a.size(); ++j) out[j] = a[j] < 0;
  return out;
}

Index count_folds(const Points3Ref& starts, const Points3Ref& ends, const FacesRef& faces, const Points3Ref& v1,
                  const FacesRef& f1, const SurfaceIndex& index1, const Points3Ref& v2, const FacesRef& f2,
                  const SurfaceIndex& index2) {
  const std::vector<char> folded = detail::FoldTest(starts, faces, v1, f1, index1, v2, f2, index2).folded(ends);
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

  const double alpha = detail::area_factor(v1, f1, v2, f2);
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
