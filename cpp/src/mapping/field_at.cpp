#include <morphomap/field_at.hpp>

#include <morphomap/curve_queries.hpp>
#include <morphomap/surface_queries.hpp>

#include "common/numbers.hpp"
#include "common/validation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>
#include <vector>

namespace morphomap {

using detail::kNaN;

namespace {

template <class Rows>
void require_finite_rows(const Rows& points, const char* name) {
  for (Index i = 0; i < points.rows(); ++i) {
    if (!points.row(i).allFinite()) detail::invalid(name, "row " + std::to_string(i) + " has a non-finite coordinate");
  }
}

double curve_length(const Points2Ref& curve, bool closed) {
  double length = 0;
  for (Index i = 0; i + 1 < curve.rows(); ++i) length += (curve.row(i + 1) - curve.row(i)).norm();
  if (closed) length += (curve.row(0) - curve.row(curve.rows() - 1)).norm();
  return length;
}

}  // namespace

DisplacementAt2 displacement_at(const DisplacementField2& field, const Points2Ref& source, bool closed,
                                const Points2Ref& points) {
  detail::require_curve(source, closed, "source");
  require_finite_rows(points, "points");
  if (field.ends.rows() != field.starts.rows()) detail::invalid("field", "starts and ends differ in length");
  const CurveIndex index(source, closed);
  const double length = curve_length(source, closed);

  // The valid vectors, sorted by where their start points lie along C1.
  std::vector<Index> valid;
  for (Index i = 0; i < field.size(); ++i) {
    if (field.valid(i)) valid.push_back(i);
  }
  Points2 starts(valid.size(), 2);
  for (std::size_t k = 0; k < valid.size(); ++k) starts.row(k) = field.starts.row(valid[k]);
  const Vector placed = index.closest_points(starts).arc_lengths;
  std::vector<std::size_t> order(valid.size());
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return placed(a) < placed(b); });
  std::vector<double> at(order.size());
  Points2 vectors(order.size(), 2);
  for (std::size_t k = 0; k < order.size(); ++k) {
    at[k] = placed(order[k]);
    const Index i = valid[order[k]];
    vectors.row(k) = field.ends.row(i) - field.starts.row(i);
  }

  const CurveHits hits = index.closest_points(points);
  DisplacementAt2 out{Points2::Constant(points.rows(), 2, kNaN), hits.distances};
  const std::size_t n = at.size();
  if (n == 0) return out;
  for (Index q = 0; q < points.rows(); ++q) {
    const double u = hits.arc_lengths(q);
    const std::size_t right = std::upper_bound(at.begin(), at.end(), u) - at.begin();
    std::size_t a, b;
    double ua, ub;
    if (right == 0 || right == n) {
      if (!closed || n == 1) {
        out.displacements.row(q) = vectors.row(right == 0 ? 0 : n - 1);
        continue;
      }
      // Between the last start and the first, across the curve's start.
      a = n - 1, b = 0;
      ua = at[a] - (right == 0 ? length : 0.0);
      ub = at[b] + (right == n ? length : 0.0);
    } else {
      a = right - 1, b = right;
      ua = at[a], ub = at[b];
    }
    const double w = ub > ua ? std::clamp((u - ua) / (ub - ua), 0.0, 1.0) : 0.0;
    out.displacements.row(q) = (1 - w) * vectors.row(a) + w * vectors.row(b);
  }
  return out;
}

DisplacementAt3 displacement_at(const DisplacementField3& field, const Points3Ref& points) {
  require_finite_rows(points, "points");
  if (field.ends.rows() != field.starts.rows()) detail::invalid("field", "starts and ends differ in length");
  if (field.faces.rows() == 0)
    detail::invalid("field", "has no faces: a 3D field needs the triangles of its start points");
  // The start triangles whose corners all have a start point, over the vertices they use.
  std::vector<Index> vertex_of(field.size(), -1), used;
  std::vector<Index> kept;
  for (Index f = 0; f < field.faces.rows(); ++f) {
    bool finite = true;
    for (int c = 0; c < 3; ++c) {
      const Index v = field.faces(f, c);
      if (v < 0 || v >= field.size())
        detail::invalid("field", "face " + std::to_string(f) + " refers to a missing vector");
      finite = finite && field.starts.row(v).allFinite();
    }
    if (finite) kept.push_back(f);
  }
  Faces faces(kept.size(), 3);
  for (std::size_t k = 0; k < kept.size(); ++k) {
    for (int c = 0; c < 3; ++c) {
      Index& slot = vertex_of[field.faces(kept[k], c)];
      if (slot < 0) slot = static_cast<Index>(used.size()), used.push_back(field.faces(kept[k], c));
      faces(k, c) = slot;
    }
  }
  DisplacementAt3 out{Points3::Constant(points.rows(), 3, kNaN), Vector::Constant(points.rows(), kNaN)};
  if (kept.empty()) return out;
  Points3 vertices(used.size(), 3);
  for (std::size_t k = 0; k < used.size(); ++k) vertices.row(k) = field.starts.row(used[k]);
  const SurfaceIndex index(vertices, faces);
  const SurfaceHits hits = index.closest_points(points);
  out.distances = hits.distances;
  for (Index q = 0; q < points.rows(); ++q) {
    const Index f = hits.faces(q);
    if (f < 0) continue;
    // Barycentric weights of the projection in its triangle.
    const Eigen::Vector3d p0 = vertices.row(faces(f, 0)), e1 = vertices.row(faces(f, 1)).transpose() - p0,
                          e2 = vertices.row(faces(f, 2)).transpose() - p0, d = hits.points.row(q).transpose() - p0;
    const double g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2), r1 = d.dot(e1), r2 = d.dot(e2);
    const double det = g11 * g22 - g12 * g12;
    double w1 = det > 0 ? (g22 * r1 - g12 * r2) / det : 0.0, w2 = det > 0 ? (g11 * r2 - g12 * r1) / det : 0.0;
    w1 = std::clamp(w1, 0.0, 1.0), w2 = std::clamp(w2, 0.0, 1.0 - w1);
    const double w[3] = {1 - w1 - w2, w1, w2};
    Eigen::RowVector3d u = Eigen::RowVector3d::Zero();
    for (int c = 0; c < 3; ++c) {
      const Index v = used[faces(f, c)];
      u += w[c] * (field.ends.row(v) - field.starts.row(v));
    }
    out.displacements.row(q) = u;  // NaN where a corner has no target
  }
  return out;
}

}  // namespace morphomap
