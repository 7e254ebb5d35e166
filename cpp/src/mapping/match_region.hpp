#pragma once
// The region between the two pieces that monotone_match pairs up, and which straight vectors lie
// inside it: the hard constraint that makes method "optimal" crossing-free by construction
// (optimal.hpp states the argument).
#include <morphomap/curve_queries.hpp>
#include <morphomap/types.hpp>

#include <string>
#include <vector>

namespace morphomap::detail {

class MatchRegion {
 public:
  // source and target as monotone_match gets them (open polylines; a closed curve cut open at the
  // anchor starts and ends at the same point). The region's boundary runs along the source, the
  // vector from its last point to the target's last point, back along the target and along the
  // vector from the target's first point to the source's first point.
  MatchRegion(const Points2Ref& source, const Points2Ref& target);

  // Empty when the region is the inside of a simple polygon, or (both pieces whole closed curves)
  // the ring between two nested disjoint curves cut along an anchor that meets them only at its
  // ends; otherwise why it is not (vectors are still tested against its boundary, but the test
  // then proves nothing).
  const std::string& why_not() const { return why_not_; }

  // For each vector from source row rows[c] to the point ends.row(c), which lies on target segment
  // segments[c] (from target row segments[c] to the next): whether all of it but its two end points
  // lies inside the region. Exact at the ends (the side each end leaves its curve to); inside, up
  // to the rounding of a line query (1e-9 of the vector's length). A vector of length 0 is
  // admitted. From all cores.
  std::vector<char> admits(const std::vector<Index>& rows, const Points2& ends,
                           const std::vector<Index>& segments) const;

 private:
  // The boundary, closed: source rows 0 .. ns - 1, then target rows mt - 1 .. 0.
  Points2 boundary_;
  Index source_rows_ = 0, target_rows_ = 0;
  std::vector<Index> previous_, next_;  // the nearest boundary vertex of another position, each way
  int side_ = 1;                        // +1: the region lies left of the boundary's direction
  std::string why_not_;
  CurveIndex index_;

  std::string check_polygon() const;
  std::string check_ring(const Points2Ref& source, const Points2Ref& target) const;
  // Whether x - v points strictly into the region at boundary vertex v.
  bool into_at_vertex(Index v, const Vec2& x) const;
  Index target_vertex(Index row) const { return source_rows_ + target_rows_ - 1 - row; }
};

}  // namespace morphomap::detail
