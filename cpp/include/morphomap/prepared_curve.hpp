#pragma once
// A curve checked and indexed once, for callers that use it in several pairs: in a time series
// frame k is the target of pair k - 1 and the source of pair k, and map_curves and quality would
// otherwise check it (simple, one loop) and build its CurveIndex several times.
#include <morphomap/curve_queries.hpp>
#include <morphomap/types.hpp>

namespace morphomap {

class PreparedCurve {
 public:
  // Copies the curve. InvalidInput naming `name` where it is not a simple curve (finite, one
  // loop, no self-intersection; closed ones enclose an area), as map_curves checks its curves.
  PreparedCurve(const Points2Ref& points, bool closed, const char* name);
  PreparedCurve(const PreparedCurve&) = delete;
  PreparedCurve& operator=(const PreparedCurve&) = delete;

  const Points2& points() const { return points_; }  // as given (a closing repeat kept)
  bool closed() const { return closed_; }
  const CurveIndex& index() const { return index_; }

  // A call that wants closed (or open) curves: InvalidInput naming `name` when this one was
  // prepared the other way (its checks and index are those of a closed, or open, curve).
  void require_closed(bool closed, const char* name) const;

 private:
  Points2 points_;
  bool closed_;
  CurveIndex index_;  // built from the copy above (declared after it)
};

}  // namespace morphomap
