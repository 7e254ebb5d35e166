#include "validation.hpp"

#include <morphomap/curve_geometry.hpp>

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <cmath>

namespace morphomap::detail {

void invalid(const char* name, const std::string& problem) {
  throw InvalidInput(std::string(name) + ": " + problem);
}

void require_finite(const Points2Ref& points, const char* name) {
  for (Index i = 0; i < points.rows(); ++i) {
    if (!std::isfinite(points(i, 0)) || !std::isfinite(points(i, 1))) {
      invalid(name, "row " + std::to_string(i) + " has a non-finite coordinate");
    }
  }
}

Index curve_size(const Points2Ref& points, bool closed) {
  Index n = points.rows();
  if (closed && n > 1 && points.row(0) == points.row(n - 1)) --n;
  return n;
}

Index require_curve(const Points2Ref& points, bool closed, const char* name) {
  require_finite(points, name);
  const Index n = curve_size(points, closed);
  const Index needed = closed ? 3 : 2;
  if (n < needed) {
    invalid(name, std::string("a") + (closed ? " closed" : "n open") + " curve needs at least " +
                      std::to_string(needed) + " points, got " + std::to_string(n));
  }
  bool moves = false;
  for (Index i = 1; i < n && !moves; ++i) moves = points.row(i) != points.row(0);
  if (!moves) invalid(name, "the curve has zero length (all points coincide)");
  return n;
}

Points2 without_repeats(const Points2Ref& points, bool closed, const char* name) {
  const Index n = require_curve(points, closed, name);
  Points2 out(n, 2);
  Index m = 0;
  for (Index i = 0; i < n; ++i) {
    if (m == 0 || points.row(i) != out.row(m - 1)) out.row(m++) = points.row(i);
  }
  if (closed) {
    while (m > 1 && out.row(m - 1) == out.row(0)) --m;
  }
  const Index needed = closed ? 3 : 2;
  if (m < needed) {
    invalid(name, "after dropping repeated points the curve has " + std::to_string(m) +
                      " distinct points, fewer than the " + std::to_string(needed) + " it needs");
  }
  out.conservativeResize(m, 2);
  return out;
}

void require_area(const Points2Ref& points, const char* name) {
  const double length = perimeter(points, true);
  if (!(std::abs(signed_area(points)) > 1e-14 * length * length)) {
    invalid(name, "the closed curve encloses zero area");
  }
}

int thread_count() { return tbb::this_task_arena::max_concurrency(); }

}  // namespace morphomap::detail
