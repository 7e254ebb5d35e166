// A curve checked and indexed once (see prepared_curve.hpp).
#include <morphomap/prepared_curve.hpp>

#include "common/validation.hpp"
#include "curves/unchecked.hpp"

#include <string>

namespace morphomap {

namespace {

// The check runs before anything is copied or indexed.
const Points2Ref& checked(const Points2Ref& points, bool closed, const char* name) {
  detail::require_simple_curve(points, closed, name);
  return points;
}

}  // namespace

PreparedCurve::PreparedCurve(const Points2Ref& points, bool closed, const char* name)
    : points_(checked(points, closed, name)),
      closed_(closed),
      index_(detail::CurveIndexUnchecked::build(points_, closed)) {}

void PreparedCurve::require_closed(bool closed, const char* name) const {
  if (closed != closed_) {
    detail::invalid(name, std::string("was prepared as ") + (closed_ ? "a closed" : "an open") +
                              " curve, but the call is for " + (closed ? "closed" : "open") + " curves");
  }
}

}  // namespace morphomap
