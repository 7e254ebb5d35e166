#include <morphomap/crossings.hpp>
#include <morphomap/curve_queries.hpp>
#include <morphomap/quality.hpp>

#include "common/numbers.hpp"
#include "common/validation.hpp"
#include "curves/arc_curve.hpp"
#include "curves/unchecked.hpp"
#include "quality/checked_quality.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace morphomap {

using detail::kNaN;

namespace {

using detail::ArcCurve;

constexpr Index kGrain = 1024;
// How far off its curve a field point may lie, relative to the curve's bounding-box diagonal:
// mapped points sit on the curve up to rounding; anything further means the wrong curve.
constexpr double kOnCurve = 1e-6;

// The points of a field as arc positions on one curve (NaN for invalid rows), with the segment
// holding each position by the rule of ArcCurve: the last segment starting at or before it.
struct Located {
  std::vector<double> arc;
  std::vector<Index> segment;
};

double diagonal(const Points2Ref& points) { return (points.colwise().maxCoeff() - points.colwise().minCoeff()).norm(); }

// index: the curve's query index (built from the curve as given, or a PreparedCurve's).
Located locate(const Points2& points, const std::vector<Index>& rows, const ArcCurve& curve, const CurveIndex& index,
               const char* which, const char* curve_name, Index total) {
  Points2 queries(static_cast<Index>(rows.size()), 2);
  for (std::size_t k = 0; k < rows.size(); ++k) queries.row(k) = points.row(rows[k]);
  // The rows are the field's finite ones.
  const CurveHits hits = detail::CurveIndexUnchecked::closest_points(index, queries);

  const double tol = kOnCurve * diagonal(curve.points());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (!(hits.distances[k] <= tol)) {
      detail::invalid("field", std::string(which) + " point " + std::to_string(rows[k]) + " is not on " + curve_name +
                                   " (distance " + std::to_string(hits.distances[k]) + ")");
    }
  }
  Located out{std::vector<double>(total, kNaN), std::vector<Index>(total, 0)};
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows.size(), kGrain),
                    [&](const tbb::blocked_range<std::size_t>& range) {
                      for (std::size_t k = range.begin(); k != range.end(); ++k) {
                        const double s = curve.wrap(hits.arc_lengths[k]);
                        out.arc[rows[k]] = s;
                        out.segment[rows[k]] = curve.segment_at(s);
                      }
                    });
  return out;
}

// The way from position a to position b: its length and direction (the shorter way round on a
// closed curve, forward at a tie).
struct Way {
  double length;
  bool forward;
};

Way way(const ArcCurve& curve, double a, double b) {
  if (!curve.closed()) return {std::abs(b - a), b >= a};
  double f = b - a;
  if (f < 0) f += curve.length();
  const double back = curve.length() - f;
  return f <= back ? Way{f, true} : Way{back, false};
}

// Calls emit(v) for each vertex v strictly inside the arc of the given way from position a
// (lying in segment seg), in walking order. Distances come from the stored arc positions, so no
// fmod per vertex; a closed curve is unrolled once past its first point.
template <class Emit>
void walk(const ArcCurve& curve, double a, Index seg, const Way& w, Emit&& emit) {
  const Index n = curve.size();
  const double len = curve.length();
  if (w.forward) {
    const Index last = curve.closed() ? seg + n : n - 1;
    for (Index v = seg + 1; v <= last; ++v) {
      const double d = (v <= n ? curve.arc(v) : curve.arc(v - n) + len) - a;
      if (d >= w.length) break;
      if (d > 0.0) emit(v < n ? v : v - n);
    }
  } else {
    const Index last = curve.closed() ? seg - n + 1 : 0;
    for (Index v = seg; v >= last; --v) {
      const double d = a - (v >= 0 ? curve.arc(v) : curve.arc(v + n) - len);
      if (d >= w.length) break;
      if (d > 0.0) emit(v >= 0 ? v : v + n);
    }
  }
}

// Mean of the finite entries (NaN if none), summed in order so that the result is reproducible.
double finite_mean(const std::vector<double>& values) {
  double sum = 0.0;
  Index count = 0;
  for (const double v : values) {
    if (std::isfinite(v)) sum += v, ++count;
  }
  return count > 0 ? sum / static_cast<double>(count) : kNaN;
}

void require_as_many_ends(const DisplacementField2& field) {
  if (field.ends.rows() != field.size()) {
    detail::invalid("field", "has " + std::to_string(field.size()) + " start points but " +
                                 std::to_string(field.ends.rows()) + " end points");
  }
}

}  // namespace

CurveQuality detail::checked_quality(const DisplacementField2& field, const Points2Ref& c1, const CurveIndex& index1,
                                     const Points2Ref& c2, const CurveIndex& index2, bool closed, bool with_crossings) {
  const Index m = field.size();
  const ArcCurve curve1 = ArcCurve::unchecked(c1, closed);
  const ArcCurve curve2 = ArcCurve::unchecked(c2, closed);

  std::vector<Index> rows;
  rows.reserve(m);
  for (Index i = 0; i < m; ++i) {
    if (field.valid(i)) rows.push_back(i);
  }
  const Located at1 = locate(field.starts, rows, curve1, index1, "start", "c1", m);
  const Located at2 = locate(field.ends, rows, curve2, index2, "end", "c2", m);

  const double alpha = curve2.length() / curve1.length();
  const Index pairs = closed && m >= 2 ? m : std::max<Index>(m - 1, 0);
  std::vector<double> ratio(pairs, kNaN), area(pairs, kNaN);
  const double* v1 = curve1.points().data();
  const double* v2 = curve2.points().data();

  tbb::parallel_for(tbb::blocked_range<Index>(0, pairs, kGrain), [&](const tbb::blocked_range<Index>& range) {
    for (Index i = range.begin(); i != range.end(); ++i) {
      const Index j = i + 1 < m ? i + 1 : 0;
      if (!(std::isfinite(at1.arc[i]) && std::isfinite(at1.arc[j]))) continue;
      const Way w1 = way(curve1, at1.arc[i], at1.arc[j]);
      const Way w2 = way(curve2, at2.arc[j], at2.arc[i]);  // from P_{i+1} back to P_i
      if (w1.length > 0.0) {
        const double r = w2.length / (alpha * w1.length) - 1.0;
        ratio[i] = r * r;
      }
      // Shoelace sum relative to p_i, which keeps it accurate far from the origin.
      const double ox = field.starts(i, 0), oy = field.starts(i, 1);
      double px = 0.0, py = 0.0, twice = 0.0;
      auto add = [&](double x, double y) {
        x -= ox, y -= oy;
        twice += px * y - py * x;
        px = x, py = y;
      };
      walk(curve1, at1.arc[i], at1.segment[i], w1, [&](Index v) { add(v1[2 * v], v1[2 * v + 1]); });
      add(field.starts(j, 0), field.starts(j, 1));
      add(field.ends(j, 0), field.ends(j, 1));
      walk(curve2, at2.arc[j], at2.segment[j], w2, [&](Index v) { add(v2[2 * v], v2[2 * v + 1]); });
      add(field.ends(i, 0), field.ends(i, 1));  // back to p_i adds nothing: it is the origin
      area[i] = 0.5 * std::abs(twice);
    }
  });

  CurveQuality q;
  q.qm1 = finite_mean(ratio);
  const double mean_area = finite_mean(area);
  if (std::isfinite(mean_area) && mean_area > 0.0) {
    for (double& a : area) {
      if (std::isfinite(a)) a = (a / mean_area - 1.0) * (a / mean_area - 1.0);
    }
    q.qm2 = finite_mean(area);
  } else {
    q.qm2 = kNaN;
  }
  q.qm = q.qm1 * q.qm2;
  q.crossings = with_crossings ? count_crossings(field.starts, field.ends) : 0;
  return q;
}

CurveQuality quality(const DisplacementField2& field, const Points2Ref& c1, const Points2Ref& c2, bool closed) {
  require_as_many_ends(field);
  detail::require_curve(c1, closed, "c1");
  detail::require_curve(c2, closed, "c2");
  return detail::checked_quality(field, c1, detail::CurveIndexUnchecked::build(c1, closed), c2,
                                 detail::CurveIndexUnchecked::build(c2, closed), closed);
}

CurveQuality quality(const DisplacementField2& field, const PreparedCurve& c1, const PreparedCurve& c2, bool closed) {
  require_as_many_ends(field);
  c1.require_closed(closed, "c1");
  c2.require_closed(closed, "c2");
  return detail::checked_quality(field, c1.points(), c1.index(), c2.points(), c2.index(), closed);
}

}  // namespace morphomap
