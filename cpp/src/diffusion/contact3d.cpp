// Contact patches between two closed surfaces (see contact3d.hpp).
#include "diffusion/contact3d.hpp"

#include "common/mesh_adjacency.hpp"
#include "diffusion/shell_mesh.hpp"

#include <morphomap/errors.hpp>

#include <Eigen/Geometry>

#include <algorithm>
#include <string>
#include <vector>

namespace morphomap::detail {

namespace {

using Vec3 = Eigen::Vector3d;

// Vertex normals averaged over a few rings: on an unsmoothed marching-cubes staircase the normals
// of neighbouring vertices differ by 90 degrees, and pulling vertices back along them folds the
// surface into itself at every step of the stairs.
Points3 smoothed_normals(const Points3Ref& vertices, const FacesRef& faces, const detail::CompressedRows& around) {
  constexpr int kRounds = 2;
  Points3 normals = vertex_normals(vertices, faces);
  Points3 next(normals.rows(), 3);
  for (int round = 0; round < kRounds; ++round) {
    for (Index v = 0; v < normals.rows(); ++v) {
      Eigen::RowVector3d sum = normals.row(v);
      for (Index k = around.first[v]; k < around.first[v + 1]; ++k) sum += normals.row(around.entries[k]);
      const double norm = sum.norm();
      next.row(v) = norm > 0.0 ? Eigen::RowVector3d(sum / norm) : Eigen::RowVector3d(normals.row(v));
    }
    normals.swap(next);
  }
  return normals;
}

// Marching cubes leaves slivers far thinner than their edges; corners of one that are pulled by
// different amounts turn it over, and the surface then meets itself. Such a face's corners are
// moved back half way towards where they were, until no face has turned (at most 10 rounds).
void keep_faces_facing(const Points3Ref& before, const FacesRef& faces, Points3& after) {
  constexpr int kRounds = 10;
  std::vector<Index> back;
  for (int round = 0; round < kRounds; ++round) {
    back.clear();
    for (Index f = 0; f < faces.rows(); ++f) {
      const Index a = faces(f, 0), b = faces(f, 1), c = faces(f, 2);
      const Vec3 was = (before.row(b) - before.row(a)).cross(before.row(c) - before.row(a)).transpose();
      const Vec3 now = (after.row(b) - after.row(a)).cross(after.row(c) - after.row(a)).transpose();
      if (now.dot(was) > 0.0) continue;
      back.insert(back.end(), {a, b, c});
    }
    if (back.empty()) return;
    std::sort(back.begin(), back.end());
    back.erase(std::unique(back.begin(), back.end()), back.end());
    for (const Index v : back) after.row(v) = 0.5 * (after.row(v) + before.row(v));
  }
}

[[noreturn]] void refuse(Index faces, double tolerance, const std::string& why) {
  throw InvalidInput("s2: coincides with s1 over a patch (" + std::to_string(faces) + " faces of s1 lie within " +
                     std::to_string(tolerance) + " of it) " + why +
                     "; diffusion cannot map these surfaces: use 'auto' (which falls back) or 'normal'");
}

}  // namespace

ClearedSource clear_contact(const Points3Ref& source_vertices, const FacesRef& source_faces,
                            const Points3Ref& target_vertices, const FacesRef& target_faces,
                            const ClosedSurface& target_surface, const SurfaceIndex& target_index, double clearance,
                            double tolerance) {
  const Index n = source_vertices.rows();
  // Only vertices within the clearance (or the touching tolerance) of the target matter here.
  const SurfaceHits hits = target_index.closest_points(source_vertices, std::max(clearance, tolerance));
  ClearedSource cleared;
  cleared.vertices = source_vertices;
  cleared.closest = hits.points;
  cleared.touching.assign(static_cast<std::size_t>(n), 0);
  std::vector<char> near(static_cast<std::size_t>(n), 0);
  bool any_near = false;
  for (Index i = 0; i < n; ++i) {
    near[i] = hits.distances[i] < clearance;
    cleared.touching[i] = hits.distances[i] <= tolerance;
    any_near = any_near || near[i];
  }
  if (!any_near) return cleared;

  for (Index f = 0; f < source_faces.rows(); ++f) {
    if (!(near[source_faces(f, 0)] && near[source_faces(f, 1)] && near[source_faces(f, 2)])) continue;
    const Vec3 a = source_vertices.row(source_faces(f, 0)).transpose(),
               b = source_vertices.row(source_faces(f, 1)).transpose(),
               c = source_vertices.row(source_faces(f, 2)).transpose();
    cleared.near_area += 0.5 * (b - a).cross(c - a).norm();
  }
  // Faces that touch at all three corners, and the corners of such faces.
  Index touching_faces = 0;
  std::vector<char> on_touching_face(static_cast<std::size_t>(n), 0);
  for (Index f = 0; f < source_faces.rows(); ++f) {
    const bool touches = cleared.touching[source_faces(f, 0)] && cleared.touching[source_faces(f, 1)] &&
                         cleared.touching[source_faces(f, 2)];
    if (!touches) continue;
    ++touching_faces;
    for (int k = 0; k < 3; ++k) on_touching_face[source_faces(f, k)] = 1;
  }

  // Which side of the target each vertex near it, or next to such a vertex, lies on.
  const detail::CompressedRows around = detail::neighbouring_vertices(n, source_faces);
  std::vector<Index> asked;
  for (Index i = 0; i < n; ++i) {
    bool ask = near[i];
    for (Index k = around.first[i]; k < around.first[i + 1] && !ask; ++k) ask = near[around.entries[k]];
    if (ask) asked.push_back(i);
  }
  Points3 queries(static_cast<Index>(asked.size()), 3);
  for (std::size_t k = 0; k < asked.size(); ++k) queries.row(static_cast<Index>(k)) = source_vertices.row(asked[k]);
  const std::vector<char> inside_answers = inside_surface(target_surface, queries);
  std::vector<char> inside(static_cast<std::size_t>(n), 0);
  for (std::size_t k = 0; k < asked.size(); ++k) inside[asked[k]] = inside_answers[k];

  const Points3 normals = smoothed_normals(source_vertices, source_faces, around);
  std::vector<char> labelled(static_cast<std::size_t>(n), 0);
  std::vector<Index> patch, stack;
  for (Index seed = 0; seed < n; ++seed) {
    if (!near[seed] || labelled[seed]) continue;
    // The patch: the connected near vertices around `seed`; its ring: their farther neighbours.
    patch.clear();
    stack.assign(1, seed);
    labelled[seed] = 1;
    Index ring_inside = 0, ring_outside = 0;
    while (!stack.empty()) {
      const Index v = stack.back();
      stack.pop_back();
      patch.push_back(v);
      for (Index k = around.first[v]; k < around.first[v + 1]; ++k) {
        const Index w = around.entries[k];
        if (!near[w]) {
          (inside[w] ? ring_inside : ring_outside) += 1;
        } else if (!labelled[w]) {
          labelled[w] = 1;
          stack.push_back(w);
        }
      }
    }
    bool has_touching_face = false;
    for (const Index v : patch) has_touching_face = has_touching_face || on_touching_face[v];
    if (ring_inside + ring_outside == 0) {
      if (!has_touching_face) continue;
      refuse(touching_faces, tolerance, "and lies within " + std::to_string(clearance) + " of it everywhere");
    }
    // A ring on both sides: the surfaces cross around this patch, which the crossing region's
    // corefinement handles. Where they also share faces, cutting those out of the region pinches
    // its pieces to the faces' rims, on which Mesh_3 crashes or runs for minutes: refused. A lone
    // vertex on the target (frames contoured on one grid share the marching-cubes planes) makes
    // the faces around it share slivers of those planes with the target, which pinch the pieces
    // to points: lifted off by the tolerance, it still maps to its closest point (both measured
    // in bench/README.md, "Real 3D stages", contact where the surfaces cross).
    const double side_share =
        static_cast<double>(std::max(ring_inside, ring_outside)) / static_cast<double>(ring_inside + ring_outside);
    if (side_share < 0.75) {
      if (has_touching_face) refuse(touching_faces, tolerance, "where they also cross");
      for (const Index v : patch) {
        if (!cleared.touching[v]) continue;
        cleared.vertices.row(v) += tolerance * normals.row(v);
        ++cleared.moved;
      }
      continue;
    }
    // Away from the target, on the patch's side: along the source normals, turned to agree with
    // the way from the target's surface into that side. The surfaces face the same way along the
    // patch (nested frames) or opposite ways (bodies that touch from outside): decided once per
    // patch, as a vertex at a crease of the target may see the normal of a face that does not
    // represent it.
    double agreement = 0.0;
    for (const Index v : patch) {
      const Index face = hits.faces[v];
      const Vec3 a = target_vertices.row(target_faces(face, 0)).transpose(),
                 b = target_vertices.row(target_faces(face, 1)).transpose(),
                 c = target_vertices.row(target_faces(face, 2)).transpose();
      agreement += normals.row(v).dot((b - a).cross(c - a).normalized().transpose());
    }
    const double side = ring_outside > ring_inside ? 1.0 : -1.0;
    const double away = agreement >= 0.0 ? side : -side;
    for (const Index v : patch) {
      const Vec3 p = source_vertices.row(v).transpose();
      // Distance to the target, positive on the patch's side.
      const double on_side = (inside[v] ? -1.0 : 1.0) * side * hits.distances[v];
      const double pull = clearance - on_side;
      if (pull <= 0.0) continue;
      cleared.vertices.row(v) = (p + pull * away * normals.row(v).transpose()).transpose();
      ++cleared.moved;
    }
  }
  keep_faces_facing(source_vertices, source_faces, cleared.vertices);
  return cleared;
}

}  // namespace morphomap::detail
