#pragma once
// The distance from a query to the nearest of a fixed set of points. nanoflann's k-d tree, not
// CGAL's Orthogonal_k_neighbor_search (a priority queue allocated per query): the meshing took ~5%
// less time at 100k faces (bench/README.md). Both are exact and sum the squared coordinate
// differences in the same order: the same distances.
#include <morphomap/types.hpp>

#include <nanoflann.hpp>

#include <array>
#include <cmath>
#include <cstdint>
#include <utility>
#include <vector>

namespace morphomap::detail {

class NearestPoint {
 public:
  // (The tree indexes the points when it is made: cloud_ is declared first.)
  explicit NearestPoint(std::vector<std::array<double, 3>> points) : cloud_{std::move(points)}, tree_(3, cloud_) {}
  NearestPoint(const NearestPoint&) = delete;  // the tree refers to cloud_
  NearestPoint& operator=(const NearestPoint&) = delete;

  static std::vector<std::array<double, 3>> rows(const Points3Ref& points) {
    std::vector<std::array<double, 3>> out(static_cast<std::size_t>(points.rows()));
    for (Index i = 0; i < points.rows(); ++i)
      out[static_cast<std::size_t>(i)] = {points(i, 0), points(i, 1), points(i, 2)};
    return out;
  }

  double distance(double x, double y, double z) const {
    const double query[3] = {x, y, z};
    std::uint32_t index = 0;
    double squared = 0.0;
    tree_.knnSearch(query, 1, &index, &squared);
    return std::sqrt(squared);
  }

 private:
  // nanoflann's dataset interface.
  struct Cloud {
    std::vector<std::array<double, 3>> points;
    std::size_t kdtree_get_point_count() const { return points.size(); }
    double kdtree_get_pt(std::size_t i, std::size_t axis) const { return points[i][axis]; }
    template <class Box>
    bool kdtree_get_bbox(Box&) const {
      return false;
    }
  };
  using Tree = nanoflann::KDTreeSingleIndexAdaptor<nanoflann::L2_Simple_Adaptor<double, Cloud>, Cloud, 3>;

  Cloud cloud_;
  Tree tree_;
};

}  // namespace morphomap::detail
