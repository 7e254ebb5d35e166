#pragma once
// Where two curves meet: the points where they cross, and the stretches where they touch or run
// together (closer than a contact tolerance, as consecutive frames segmented on one pixel grid do
// wherever the tissue did not move). The mapping splits both curves there, as the paper splits
// them at intersection points.
#include <morphomap/curve_queries.hpp>
#include <morphomap/types.hpp>

#include "curves/arc_curve.hpp"

#include <vector>

namespace morphomap::detail {

struct Meeting {
  // Arc positions of the two ends on the source (end >= begin; on a closed curve the end may lie
  // past the length when the stretch runs over the first point) and on the target.
  double source_begin = 0.0, source_end = 0.0;
  double target_begin = 0.0, target_end = 0.0;
  Vec2 source_point_begin, source_point_end, target_point_begin, target_point_end;
  // A crossing point (all four points are the crossing), or a contact stretch: the source
  // vertices first_vertex .. last_vertex (wrapping on a closed curve), each within the tolerance
  // of the target.
  bool crossing = false;
  Index first_vertex = -1, last_vertex = -1;
};

// The default contact tolerance: 1% of the finer of the two curves' median segment lengths.
double default_contact_tolerance(const ArcCurve& source, const ArcCurve& target);

// The meetings of source and target in order along the source. A contact stretch is a run of
// source vertices within `tolerance` of the target, consecutive ones joined where the target
// between their closest points also stays within `tolerance` of the source (so a run does not
// jump across a gap); a single such vertex is a touching point. Crossings that lie on a stretch
// (within the tolerance) belong to it; the others are meetings of their own. The indexes are
// those of the two curves (the caller's, built once per call).
std::vector<Meeting> find_meetings(const ArcCurve& source, const ArcCurve& target, const CurveIndex& source_index,
                                   const CurveIndex& target_index, const CurveIntersections& crossings,
                                   double tolerance);

// The meetings whose target positions follow each other along the target in `direction`
// (+1 forward, -1 backward), in source order: all of them when they already do, else a greedy
// subsequence (pieces between meetings that do not can not be paired).
std::vector<Meeting> meetings_in_order(const std::vector<Meeting>& meetings, const ArcCurve& target, int direction,
                                       bool* all_in_order);

}  // namespace morphomap::detail
