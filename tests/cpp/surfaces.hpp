#pragma once
// Closed triangle surfaces built in code, shared by the C++ unit tests.
#include <morphomap/types.hpp>

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <map>
#include <utility>
#include <vector>

namespace morphomap_test {

using morphomap::Faces;
using morphomap::Index;
using morphomap::Points3;

struct Surface {
  Points3 vertices;
  Faces faces;
};

// Unit icosphere: the icosahedron with each triangle split in four `levels` times, outwards.
inline Surface icosphere(int levels) {
  const double t = (1.0 + std::sqrt(5.0)) / 2.0;
  std::vector<Eigen::Vector3d> v = {{-1, t, 0},  {1, t, 0},  {-1, -t, 0}, {1, -t, 0}, {0, -1, t},  {0, 1, t},
                                    {0, -1, -t}, {0, 1, -t}, {t, 0, -1},  {t, 0, 1},  {-t, 0, -1}, {-t, 0, 1}};
  std::vector<std::array<Index, 3>> f = {{0, 11, 5}, {0, 5, 1},  {0, 1, 7},   {0, 7, 10}, {0, 10, 11},
                                         {1, 5, 9},  {5, 11, 4}, {11, 10, 2}, {10, 7, 6}, {7, 1, 8},
                                         {3, 9, 4},  {3, 4, 2},  {3, 2, 6},   {3, 6, 8},  {3, 8, 9},
                                         {4, 9, 5},  {2, 4, 11}, {6, 2, 10},  {8, 6, 7},  {9, 8, 1}};
  for (auto& p : v) p.normalize();
  for (int level = 0; level < levels; ++level) {
    std::map<std::pair<Index, Index>, Index> middle;
    auto mid = [&](Index a, Index b) {
      const auto key = std::minmax(a, b);
      const auto found = middle.find(key);
      if (found != middle.end()) return found->second;
      v.push_back((v[a] + v[b]).normalized());
      return middle[key] = static_cast<Index>(v.size()) - 1;
    };
    std::vector<std::array<Index, 3>> next;
    for (const auto& [a, b, c] : f) {
      const Index ab = mid(a, b), bc = mid(b, c), ca = mid(c, a);
      next.push_back({a, ab, ca});
      next.push_back({b, bc, ab});
      next.push_back({c, ca, bc});
      next.push_back({ab, bc, ca});
    }
    f = std::move(next);
  }
  Surface s;
  s.vertices.resize(static_cast<Index>(v.size()), 3);
  for (std::size_t i = 0; i < v.size(); ++i) s.vertices.row(static_cast<Index>(i)) = v[i].transpose();
  s.faces.resize(static_cast<Index>(f.size()), 3);
  for (std::size_t i = 0; i < f.size(); ++i) s.faces.row(static_cast<Index>(i)) << f[i][0], f[i][1], f[i][2];
  return s;
}

inline Surface scaled(Surface s, double x, double y, double z) {
  s.vertices.col(0) *= x;
  s.vertices.col(1) *= y;
  s.vertices.col(2) *= z;
  return s;
}

inline Surface flipped(Surface s) {
  s.faces.col(1).swap(s.faces.col(2));
  return s;
}

// The surface moved by (x, y, z).
inline Surface moved(Surface s, double x, double y, double z) {
  s.vertices.rowwise() += Eigen::RowVector3d(x, y, z);
  return s;
}

// Both surfaces as one mesh (two components).
inline Surface joined(const Surface& a, const Surface& b) {
  Surface s;
  s.vertices.resize(a.vertices.rows() + b.vertices.rows(), 3);
  s.vertices << a.vertices, b.vertices;
  s.faces.resize(a.faces.rows() + b.faces.rows(), 3);
  s.faces << a.faces, (b.faces.array() + a.vertices.rows()).matrix();
  return s;
}

}  // namespace morphomap_test
