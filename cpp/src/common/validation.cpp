#include "common/validation.hpp"

#include "curves/unchecked.hpp"

#include <tbb/info.h>
#include <tbb/task_arena.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <unordered_map>
#include <vector>

namespace morphomap::detail {

void invalid(const char* name, const std::string& problem) { throw InvalidInput(std::string(name) + ": " + problem); }

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
  require_curve(points, closed, name);
  return drop_repeats(points, closed, name);
}

Points2 drop_repeats(const Points2Ref& points, bool closed, const char* name) {
  const Index n = curve_size(points, closed);
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
  const double length = perimeter_unchecked(points, true);
  if (!(std::abs(signed_area_unchecked(points)) > 1e-14 * length * length)) {
    invalid(name, "the closed curve encloses zero area");
  }
}

Points2 oriented_closed_curve(const Points2Ref& points, const char* name, int& turn) {
  Points2 q = without_repeats(points, true, name);
  try {
    turn = orientation_unchecked(q);
  } catch (const InvalidInput&) {
    invalid(name, "the closed curve encloses zero area");
  }
  return q;
}

namespace {

// Loops closed by a point that repeats one met earlier on the way (not just before it): the
// points from the first visit to the return form a loop, and the walk goes on from the first
// visit. A leftover of at least three points is a loop too (closed curves close themselves).
struct Loops {
  Index count = 0;
  Index first_repeat = -1, first_visit = -1;  // rows of the first repeat found
};

Loops count_loops(const Points2Ref& points, Index n, bool closed) {
  auto key = [&](Index i) {
    const double xy[2] = {points(i, 0) == 0.0 ? 0.0 : points(i, 0), points(i, 1) == 0.0 ? 0.0 : points(i, 1)};
    std::uint64_t bits[2];
    std::memcpy(bits, xy, sizeof bits);
    return std::make_pair(bits[0], bits[1]);
  };
  struct Hash {
    std::size_t operator()(const std::pair<std::uint64_t, std::uint64_t>& k) const {
      return std::hash<std::uint64_t>()(k.first * 0x9E3779B97F4A7C15ULL ^ k.second);
    }
  };
  std::unordered_map<std::pair<std::uint64_t, std::uint64_t>, std::size_t, Hash> position;  // in the walk
  std::vector<Index> walk;
  Loops loops;
  for (Index i = 0; i < n; ++i) {
    if (!walk.empty() && points.row(i) == points.row(walk.back())) continue;  // consecutive repeat
    const auto found = position.find(key(i));
    if (found == position.end()) {
      position.emplace(key(i), walk.size());
      walk.push_back(i);
      continue;
    }
    const std::size_t at = found->second;
    if (walk.size() - at >= 3) ++loops.count;
    if (loops.first_repeat < 0) loops.first_repeat = i, loops.first_visit = walk[at];
    for (std::size_t k = at + 1; k < walk.size(); ++k) position.erase(key(walk[k]));
    walk.resize(at + 1);
  }
  if (loops.first_repeat >= 0 && (closed ? walk.size() >= 3 : walk.size() >= 2)) ++loops.count;
  return loops;
}

bool all_on_one_line(const Points2Ref& points) {
  const Eigen::RowVector2d origin = points.row(0);
  Index far = 0;
  for (Index i = 1; i < points.rows(); ++i) {
    if ((points.row(i) - origin).squaredNorm() > (points.row(far) - origin).squaredNorm()) far = i;
  }
  const Eigen::RowVector2d axis = points.row(far) - origin;
  const double length = axis.norm();
  for (Index i = 0; i < points.rows(); ++i) {
    const Eigen::RowVector2d d = points.row(i) - origin;
    if (std::abs(d.x() * axis.y() - d.y() * axis.x()) > 1e-12 * length * length) return false;
  }
  return true;
}

}  // namespace

Index require_simple_curve(const Points2Ref& points, bool closed, const char* name) {
  const Index n = require_curve(points, closed, name);
  const Loops loops = count_loops(points, n, closed);
  if (loops.count >= 2) {
    invalid(name, "the points form " + std::to_string(loops.count) + " loops (row " +
                      std::to_string(loops.first_repeat) + " returns to row " + std::to_string(loops.first_visit) +
                      "), as when the contours of several objects are joined into one array: pass one object's "
                      "curve (morphomap.split_components(points) separates them)");
  }
  // Points all on one line bound nothing: say so rather than that the curve meets itself.
  if (closed && all_on_one_line(points.topRows(n))) require_area(points.topRows(n), name);
  require_no_self_intersection(points.topRows(n), closed, name);
  if (closed) require_area(points.topRows(n), name);
  return n;
}

void require_contact_tolerance(double value) {
  if (!std::isfinite(value)) invalid("contact_tolerance", "must be finite, got " + std::to_string(value));
}

void require_mesh_size(double value) {
  if (!(value >= 0.0) || !std::isfinite(value)) invalid("mesh_size", "must be a finite length >= 0 (0: automatic)");
}

void require_diffusion_options(const DiffusionOptions& options) {
  require_mesh_size(options.mesh_size);
  if (!(options.mesh_fraction > 0.0) || !std::isfinite(options.mesh_fraction)) {
    invalid("mesh_fraction", "must be a finite number > 0");
  }
}

int thread_count() { return tbb::this_task_arena::max_concurrency(); }

}  // namespace morphomap::detail
