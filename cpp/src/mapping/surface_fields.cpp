// A field of S2's vertices carried onto S1's, and lost ends filled from their neighbours'
// (surface_fields.hpp).
#include "mapping/surface_fields.hpp"

#include "common/mesh_adjacency.hpp"
#include "surfaces/surface_util.hpp"

#include <tbb/parallel_for.h>
#include <Eigen/Geometry>
#include <Eigen/Sparse>

#include <algorithm>
#include <limits>
#include <vector>

namespace morphomap::detail {

DisplacementField3 carried_onto_source(const DisplacementField3& reverse, const Points3Ref& v1, const FacesRef& f1) {
  const double nan = std::numeric_limits<double>::quiet_NaN();
  DisplacementField3 field;
  field.starts = v1;
  field.faces = f1;
  field.ends = Points3::Constant(v1.rows(), 3, nan);
  field.methods.assign(static_cast<std::size_t>(v1.rows()), Method::minimal_distance);
  // The image of S2's triangles on S1: those whose three corners were mapped and whose image has
  // an area (a collapsed one has no barycentric coordinates).
  std::vector<Index> kept;
  for (Index k = 0; k < reverse.faces.rows(); ++k) {
    bool mapped = true;
    for (int j = 0; j < 3; ++j) mapped = mapped && reverse.starts.row(reverse.faces(k, j)).allFinite();
    if (!mapped) continue;
    const V3 a = reverse.starts.row(reverse.faces(k, 0)).transpose();
    const V3 b = reverse.starts.row(reverse.faces(k, 1)).transpose();
    const V3 c = reverse.starts.row(reverse.faces(k, 2)).transpose();
    if ((b - a).cross(c - a).squaredNorm() > 0.0) kept.push_back(k);
  }
  if (kept.empty()) return field;
  Faces image_faces(static_cast<Index>(kept.size()), 3);
  for (std::size_t k = 0; k < kept.size(); ++k) image_faces.row(static_cast<Index>(k)) = reverse.faces.row(kept[k]);
  // Unmapped rows are used by no kept face; the index wants finite coordinates all the same.
  Points3 image = reverse.starts;
  for (Index i = 0; i < image.rows(); ++i) {
    if (!image.row(i).allFinite()) image.row(i).setZero();
  }
  const SurfaceHits hits = SurfaceIndex(image, image_faces).closest_points(v1);
  tbb::parallel_for(Index(0), v1.rows(), [&](Index i) {
    const Index k = hits.faces[i];
    if (k < 0) return;
    const Index a = image_faces(k, 0), b = image_faces(k, 1), c = image_faces(k, 2);
    const V3 pa = image.row(a).transpose(), pb = image.row(b).transpose(), pc = image.row(c).transpose();
    const double reach = std::max({(pb - pa).norm(), (pc - pb).norm(), (pa - pc).norm()});
    if (!(hits.distances[i] <= reach)) return;
    V3 w = barycentric(pa, pb, pc, hits.points.row(i).transpose());
    w = w.cwiseMax(0.0);
    w /= w.sum();
    field.ends.row(i) = w[0] * reverse.ends.row(a) + w[1] * reverse.ends.row(b) + w[2] * reverse.ends.row(c);
    int nearest = 0;
    w.maxCoeff(&nearest);
    field.methods[static_cast<std::size_t>(i)] = reverse.methods[static_cast<std::size_t>(image_faces(k, nearest))];
  });
  return field;
}

Index fill_lost_ends(DisplacementField3& field, const SurfaceIndex& target_index) {
  const Index n = field.size();
  std::vector<Index> unknown_of(static_cast<std::size_t>(n), -1);
  std::vector<Index> unknowns;
  for (Index i = 0; i < n; ++i) {
    if (field.starts.row(i).allFinite() && !field.ends.row(i).allFinite()) {
      unknown_of[static_cast<std::size_t>(i)] = static_cast<Index>(unknowns.size());
      unknowns.push_back(i);
    }
  }
  if (unknowns.empty()) return 0;
  const CompressedRows ring = neighbouring_vertices(n, field.faces);
  // Which unknowns reach a known end through unknowns: a component of lost vertices alone (or
  // the whole surface lost) has nothing to interpolate from and stays NaN.
  std::vector<char> reached(unknowns.size(), 0);
  std::vector<Index> front;
  for (std::size_t u = 0; u < unknowns.size(); ++u) {
    const Index v = unknowns[u];
    for (Index k = ring.first[v]; k < ring.first[v + 1]; ++k) {
      if (unknown_of[static_cast<std::size_t>(ring.entries[k])] < 0 && field.ends.row(ring.entries[k]).allFinite()) {
        reached[u] = 1;
        front.push_back(static_cast<Index>(u));
        break;
      }
    }
  }
  while (!front.empty()) {
    const Index v = unknowns[static_cast<std::size_t>(front.back())];
    front.pop_back();
    for (Index k = ring.first[v]; k < ring.first[v + 1]; ++k) {
      const Index w = unknown_of[static_cast<std::size_t>(ring.entries[k])];
      if (w >= 0 && !reached[static_cast<std::size_t>(w)]) {
        reached[static_cast<std::size_t>(w)] = 1;
        front.push_back(w);
      }
    }
  }
  // The discrete Laplace equation over the reached unknowns, the known ends (and unreached
  // unknowns, which have none) as its boundary: sum over neighbours w of (x_v - x_w) = 0.
  const Index m = static_cast<Index>(unknowns.size());
  std::vector<Eigen::Triplet<double>> entries;
  Eigen::MatrixX3d rhs = Eigen::MatrixX3d::Zero(m, 3);
  for (Index u = 0; u < m; ++u) {
    const Index v = unknowns[static_cast<std::size_t>(u)];
    if (!reached[static_cast<std::size_t>(u)]) {
      entries.emplace_back(u, u, 1.0);
      continue;
    }
    double degree = 0.0;
    for (Index k = ring.first[v]; k < ring.first[v + 1]; ++k) {
      const Index w = ring.entries[k];
      const Index wu = unknown_of[static_cast<std::size_t>(w)];
      if (wu >= 0) {
        if (!reached[static_cast<std::size_t>(wu)]) continue;
        entries.emplace_back(u, wu, -1.0);
      } else if (field.ends.row(w).allFinite()) {
        rhs.row(u) += field.ends.row(w);
      } else {
        continue;  // a vertex with no start (not on the surface): no neighbour
      }
      degree += 1.0;
    }
    entries.emplace_back(u, u, degree);
  }
  Eigen::SparseMatrix<double> laplacian(m, m);
  laplacian.setFromTriplets(entries.begin(), entries.end());
  const Eigen::SimplicialLDLT<Eigen::SparseMatrix<double>> solver(laplacian);
  if (solver.info() != Eigen::Success) return 0;
  const Eigen::MatrixX3d x = solver.solve(rhs);
  Points3 guesses(m, 3);
  for (Index u = 0; u < m; ++u) guesses.row(u) = x.row(u);
  const SurfaceHits on_target = target_index.closest_points(guesses);
  Index filled = 0;
  for (Index u = 0; u < m; ++u) {
    if (!reached[static_cast<std::size_t>(u)] || !on_target.points.row(u).allFinite()) continue;
    field.ends.row(unknowns[static_cast<std::size_t>(u)]) = on_target.points.row(u);
    ++filled;
  }
  return filled;
}

std::vector<Index> rows_near(const DisplacementField3& field, const std::vector<char>& faces_flagged, int rings) {
  std::vector<char> near(static_cast<std::size_t>(field.size()), 0);
  std::vector<Index> rows;
  for (Index k = 0; k < field.faces.rows(); ++k) {
    if (!faces_flagged[static_cast<std::size_t>(k)]) continue;
    for (int j = 0; j < 3; ++j) {
      const Index v = field.faces(k, j);
      if (!near[static_cast<std::size_t>(v)]) near[static_cast<std::size_t>(v)] = 1, rows.push_back(v);
    }
  }
  const CompressedRows ring = neighbouring_vertices(field.size(), field.faces);
  std::size_t begin = 0;
  for (int r = 0; r < rings; ++r) {
    const std::size_t end = rows.size();
    for (std::size_t i = begin; i < end; ++i) {
      for (Index k = ring.first[rows[i]]; k < ring.first[rows[i] + 1]; ++k) {
        const Index w = ring.entries[k];
        if (!near[static_cast<std::size_t>(w)]) near[static_cast<std::size_t>(w)] = 1, rows.push_back(w);
      }
    }
    begin = end;
  }
  return rows;
}

}  // namespace morphomap::detail
