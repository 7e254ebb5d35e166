// Triangle-surface checks and vertex normals (no Embree, no CGAL).
#include <morphomap/surface_queries.hpp>

#include "common/validation.hpp"
#include "surfaces/surface_util.hpp"

#include <tbb/parallel_sort.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <utility>
#include <vector>

namespace morphomap {

namespace detail {

void require_finite3(const Points3Ref& points, const char* name) {
  for (Index i = 0; i < points.rows(); ++i) {
    if (!points.row(i).allFinite()) invalid(name, "row " + std::to_string(i) + " has a non-finite coordinate");
  }
}

void require_face_indices(const FacesRef& faces, Index vertex_count, const char* name) {
  for (Index j = 0; j < faces.rows(); ++j) {
    for (int k = 0; k < 3; ++k) {
      const Index v = faces(j, k);
      if (v < 0 || v >= vertex_count) {
        invalid(name, "vertex index " + std::to_string(v) + " is outside 0.." + std::to_string(vertex_count - 1) +
                          " (face " + std::to_string(j) + ")");
      }
    }
  }
}

void require_outward(double volume, const char* name) {
  if (!(volume > 0.0)) {
    invalid(name, "the faces are oriented inwards (the enclosed volume comes out as " + std::to_string(volume) +
                      "): reverse the order of the vertices of every face (faces[:, ::-1]; trimesh: mesh.invert())");
  }
}

bool encloses_volume(double volume, const Points3Ref& vertices) {
  const double scale = (vertices.colwise().maxCoeff() - vertices.colwise().minCoeff()).norm();
  return volume > 1e-12 * scale * scale * scale;
}

void require_volume(double volume, const Points3Ref& vertices, const char* name) {
  if (!encloses_volume(volume, vertices)) invalid(name, "encloses no volume");
}

}  // namespace detail

using detail::V3;

Points3 vertex_normals(const Points3Ref& vertices, const FacesRef& faces) {
  detail::require_finite3(vertices, "vertices");
  detail::require_face_indices(faces, vertices.rows(), "faces");
  Points3 sum = Points3::Zero(vertices.rows(), 3);
  for (Index j = 0; j < faces.rows(); ++j) {
    const V3 p[3] = {detail::corner(vertices, faces, j, 0), detail::corner(vertices, faces, j, 1),
                     detail::corner(vertices, faces, j, 2)};
    const V3 n = (p[1] - p[0]).cross(p[2] - p[0]);
    const double len = n.norm();
    if (!(len > 0)) continue;  // a degenerate triangle has no direction to contribute
    for (int k = 0; k < 3; ++k) {
      const V3 e1 = p[(k + 1) % 3] - p[k], e2 = p[(k + 2) % 3] - p[k];
      // atan2 of |cross| and dot stays accurate for angles near 0 and pi, unlike acos.
      const double angle = std::atan2(e1.cross(e2).norm(), e1.dot(e2));
      sum.row(faces(j, k)) += (angle / len) * n.transpose();
    }
  }
  for (Index i = 0; i < sum.rows(); ++i) {
    const double len = sum.row(i).norm();
    if (len > 0) {
      sum.row(i) /= len;
    } else {
      sum.row(i).setConstant(std::numeric_limits<double>::quiet_NaN());  // isolated vertex
    }
  }
  return sum;
}

double check_closed_surface(const Points3Ref& vertices, const FacesRef& faces, const char* name) {
  if (faces.rows() < 4) {
    detail::invalid(name, "a closed surface needs at least 4 faces, got " + std::to_string(faces.rows()));
  }
  // Named "NAME vertices" and "NAME faces": the words Python's own array checks use, as this is
  // the one check of these rules on the way to mapping, quality and diffusion.
  const std::string vertices_name = std::string(name) + " vertices", faces_name = std::string(name) + " faces";
  detail::require_finite3(vertices, vertices_name.c_str());
  detail::require_face_indices(faces, vertices.rows(), faces_name.c_str());
  // Coordinates about the centre of the bounding box keep the volume sum accurate far from 0.
  const V3 centre = 0.5 * (vertices.colwise().minCoeff() + vertices.colwise().maxCoeff()).transpose();
  double volume = 0.0;
  for (Index j = 0; j < faces.rows(); ++j) {
    const V3 a = detail::corner(vertices, faces, j, 0) - centre, b = detail::corner(vertices, faces, j, 1) - centre,
             c = detail::corner(vertices, faces, j, 2) - centre;
    const V3 n = (b - a).cross(c - a);
    if (n.x() == 0.0 && n.y() == 0.0 && n.z() == 0.0) {
      detail::invalid(name, "face " + std::to_string(j) + " has zero area");
    }
    volume += a.dot(b.cross(c));
  }
  // Closed and consistently oriented: each directed edge occurs once and its reverse once too.
  std::vector<std::pair<Index, Index>> edges;
  edges.reserve(3 * faces.rows());
  for (Index j = 0; j < faces.rows(); ++j) {
    for (int k = 0; k < 3; ++k) edges.emplace_back(faces(j, k), faces(j, (k + 1) % 3));
  }
  tbb::parallel_sort(edges.begin(), edges.end());
  const auto edge = [](Index a, Index b) { return "edge (" + std::to_string(a) + ", " + std::to_string(b) + ")"; };
  for (std::size_t e = 0; e < edges.size(); ++e) {
    const auto [a, b] = edges[e];
    if (e + 1 < edges.size() && edges[e + 1] == edges[e]) {
      detail::invalid(name, edge(a, b) +
                                " is used twice in the same direction: the faces are not "
                                "consistently oriented, or more than two faces meet at the edge");
    }
    if (!std::binary_search(edges.begin(), edges.end(), std::make_pair(b, a))) {
      detail::invalid(name, "the surface is not closed: " + edge(a, b) +
                                " belongs to one face only "
                                "(or its neighbour is oriented the other way)");
    }
  }
  // Every vertex used (an unused one has no normal, and no place on the surface).
  std::vector<char> used(vertices.rows(), 0);
  for (Index j = 0; j < faces.rows(); ++j) {
    for (int k = 0; k < 3; ++k) used[faces(j, k)] = 1;
  }
  const auto unused = std::find(used.begin(), used.end(), 0);
  if (unused != used.end()) {
    detail::invalid(name, "vertex " + std::to_string(unused - used.begin()) + " (of " +
                              std::to_string(vertices.rows()) +
                              ") is used by no face: drop unused vertices first (trimesh: "
                              "mesh.remove_unreferenced_vertices())");
  }
  // One shell: debris segmented with the organ is a second closed component.
  std::vector<Index> parent(vertices.rows());
  for (Index i = 0; i < vertices.rows(); ++i) parent[i] = i;
  auto root = [&](Index i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (Index j = 0; j < faces.rows(); ++j) {
    for (int k = 1; k < 3; ++k) {
      const Index a = root(faces(j, 0)), b = root(faces(j, k));
      if (a != b) parent[std::max(a, b)] = std::min(a, b);
    }
  }
  std::vector<Index> faces_of(vertices.rows(), 0);
  for (Index j = 0; j < faces.rows(); ++j) ++faces_of[root(faces(j, 0))];
  std::vector<Index> sizes;
  for (Index i = 0; i < vertices.rows(); ++i) {
    if (faces_of[i] > 0) sizes.push_back(faces_of[i]);
  }
  if (sizes.size() > 1) {
    std::sort(sizes.rbegin(), sizes.rend());
    std::string listed;
    for (std::size_t k = 0; k < sizes.size() && k < 5; ++k) listed += (k ? ", " : "") + std::to_string(sizes[k]);
    if (sizes.size() > 5) listed += ", ...";
    detail::invalid(name, "the surface has " + std::to_string(sizes.size()) + " separate components (" + listed +
                              " faces), as when debris is segmented with the organ: pass one object "
                              "(morphomap.split_components(mesh) separates them)");
  }
  return volume / 6.0;
}

}  // namespace morphomap
