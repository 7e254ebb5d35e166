// The paper's 2D mapping: basic algorithms (minimal distance, normal, uniform) on a source curve
// and a target curve, or on each pair of segments between their intersection points (split), with
// the reverse and transform extensions around them.
#include <morphomap/curve_geometry.hpp>
#include <morphomap/crossings.hpp>
#include <morphomap/curve_queries.hpp>
#include <morphomap/laplace.hpp>
#include <morphomap/mapping.hpp>
#include <morphomap/resample.hpp>
#include <morphomap/transform.hpp>

#include "arc_curve.hpp"
#include "validation.hpp"

#include <unsupported/Eigen/FFT>

#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <vector>

namespace morphomap {

std::string method_name(Method method) {
  switch (method) {
    case Method::minimal_distance: return "minimal_distance";
    case Method::normal: return "normal";
    case Method::diffusion: return "diffusion";
    case Method::uniform: return "uniform";
  }
  return "unknown";
}

namespace {

using detail::ArcCurve;
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();

// A piece of the source (the whole curve, or the stretch between two crossings) with its start
// points, and the piece of the target it maps onto.
struct Job {
  Points2 source;                // the source polyline
  bool source_closed = false;
  std::vector<Index> start_rows;  // rows of source that are start points, in order along it
  Points2 normals;               // normal mapping: the normal of the whole curve at each start
  Vector fractions;              // uniform: arc position along the source / its length
  Points2 target;
  bool target_closed = false;
  double anchor = 0.0;           // uniform: target arc position where fraction 0 lands
  int direction = 1;             // uniform: +1 forward along the target, -1 backward
};

// Vectors with the arc position of their start along the whole source curve, to order them.
struct Vectors {
  Points2 starts, ends;
  std::vector<Method> methods;
  std::vector<double> keys;
};

Points2 start_points(const Job& job) {
  Points2 starts(job.start_rows.size(), 2);
  for (std::size_t j = 0; j < job.start_rows.size(); ++j) starts.row(j) = job.source.row(job.start_rows[j]);
  return starts;
}

Points2 basic_ends(MapMethod method, const Job& job, const Points2& starts) {
  if (starts.rows() == 0) return Points2(0, 2);
  const ArcCurve target(job.target, job.target_closed, "c2");
  if (target.length() == 0.0) return job.target.row(0).replicate(starts.rows(), 1);
  switch (method) {
    case MapMethod::minimal_distance:
      return CurveIndex(job.target, job.target_closed).closest_points(starts).points;
    case MapMethod::normal:
      return CurveIndex(job.target, job.target_closed).line_intersections(starts, job.normals).points;
    case MapMethod::uniform: {
      Points2 ends(starts.rows(), 2);
      for (Index i = 0; i < ends.rows(); ++i) {
        const double s = job.anchor + job.direction * job.fractions[i] * target.length();
        ends.row(i) = target.point_at(s).transpose();
      }
      return ends;
    }
    case MapMethod::diffusion: {
      const DiffusionSolution solution = solve_diffusion(job.source, job.target, job.source_closed);
      Points2 ends(starts.rows(), 2);
      for (std::size_t j = 0; j < job.start_rows.size(); ++j) ends.row(j) = solution.ends.row(job.start_rows[j]);
      return ends;
    }
    default:
      detail::invalid("method", "not a basic algorithm");
  }
}

Method basic_method(MapMethod method) {
  switch (method) {
    case MapMethod::minimal_distance: return Method::minimal_distance;
    case MapMethod::normal: return Method::normal;
    case MapMethod::uniform: return Method::uniform;
    default: return Method::diffusion;
  }
}

// Start points per gap: the mean distance from the starts to the target over their mean spacing
// along the source.
double point_density(const Job& job, const Points2& starts) {
  const double gap = CurveIndex(job.target, job.target_closed).closest_points(starts).distances.mean();
  const double spacing = ArcCurve(job.source, job.source_closed, "c1").length() / starts.rows();
  return spacing > 0.0 ? gap / spacing : 0.0;
}

// A basic algorithm run backwards on one job (the paper's reverse mapping): from the target's
// points (but shared crossings) to the source, flipped.
Vectors reverse(MapMethod method, const Job& job, const ArcCurve& whole_source) {
  Job back;
  back.source = job.target;
  back.source_closed = job.target_closed;
  back.target = job.source;
  back.target_closed = job.source_closed;
  const Index n = job.target.rows();
  for (Index i = 0; i < n; ++i) {
    const bool shared = !job.target_closed && ((i == 0 && job.target.row(0) == job.source.row(0)) ||
                                               (i == n - 1 && job.target.row(n - 1) == job.source.row(job.source.rows() - 1)));
    if (!shared) back.start_rows.push_back(i);
  }
  Vectors v;
  v.ends = start_points(back);
  if (method == MapMethod::normal) back.normals = normals(back.source, back.source_closed)(back.start_rows, Eigen::all);
  v.starts = basic_ends(method, back, v.ends);
  v.methods.assign(v.starts.rows(), basic_method(method));
  v.keys.assign(v.starts.rows(), std::numeric_limits<double>::infinity());
  std::vector<Index> found;
  for (Index i = 0; i < v.starts.rows(); ++i) {
    if (v.starts.row(i).allFinite()) found.push_back(i);
  }
  if (!found.empty()) {
    Points2 located(found.size(), 2);
    for (std::size_t j = 0; j < found.size(); ++j) located.row(j) = v.starts.row(found[j]);
    const Vector arcs = CurveIndex(whole_source.points(), whole_source.closed()).closest_points(located).arc_lengths;
    for (std::size_t j = 0; j < found.size(); ++j) v.keys[found[j]] = whole_source.wrap(arcs[j]);
  }
  for (Index i = 0; i < v.starts.rows(); ++i) {
    if (!v.starts.row(i).allFinite()) v.ends.row(i).setConstant(kNaN);
  }
  return v;
}

// One job with one algorithm; "auto" is the paper's Algorithm 1 on the job: normal mapping, and
// reverse diffusion instead when normal mapping gives crossings or misses. With a density
// threshold, the first attempt is reverse minimal distance where the start points are denser
// than the threshold (the paper's "limiting case of an infinite number of points").
Vectors run(MapMethod method, const Job& job, const std::vector<double>& start_keys,
            const ArcCurve& whole_source, double density_threshold) {
  const bool automatic = method == MapMethod::automatic;
  Vectors v;
  v.starts = start_points(job);
  v.keys = start_keys;
  if (automatic && density_threshold > 0.0 && v.starts.rows() > 0 &&
      point_density(job, v.starts) > density_threshold) {
    v = reverse(MapMethod::minimal_distance, job, whole_source);
  } else {
    const MapMethod first = automatic ? MapMethod::normal : method;
    v.ends = basic_ends(first, job, v.starts);
    v.methods.assign(v.starts.rows(), basic_method(first));
  }
  if (automatic && v.starts.rows() > 0 &&
      (!v.ends.allFinite() || !v.starts.allFinite() || count_crossings(v.starts, v.ends) > 0)) {
    return reverse(MapMethod::diffusion, job, whole_source);
  }
  return v;
}

// Closed curves without a known pair of anchors: the start of the target (walking in direction)
// such that equally spaced points of both curves, matched in order, are closest in the sum of
// squared displacements. A circular cross-correlation by FFT over 2^k samples.
double best_anchor(const ArcCurve& source, const ArcCurve& target, int direction) {
  Index m = 64;
  while (m < 2 * source.size()) m *= 2;
  std::vector<std::complex<double>> s(m), t(m), fs, ft, product(m), correlation;
  for (Index j = 0; j < m; ++j) {
    const Vec2 p = source.point_at(source.length() * j / m);
    const Vec2 q = target.point_at(direction * target.length() * j / m);
    s[j] = {p.x(), p.y()};
    t[j] = {q.x(), q.y()};
  }
  Eigen::FFT<double> fft;
  fft.fwd(fs, s);
  fft.fwd(ft, t);
  for (Index j = 0; j < m; ++j) product[j] = std::conj(fs[j]) * ft[j];
  fft.inv(correlation, product);
  // sum_i |s_i - t_{i+k}|^2 is smallest where Re sum_i conj(s_i) t_{i+k} is largest.
  Index best = 0;
  for (Index k = 1; k < m; ++k) {
    if (correlation[k].real() > correlation[best].real()) best = k;
  }
  return direction * target.length() * best / m;
}

// +1 when both closed curves turn the same way.
int relative_direction(const ArcCurve& source, const ArcCurve& target) {
  return orientation(source.points()) == orientation(target.points()) ? 1 : -1;
}

// Positions of the crossings on the target, in the order met along the source, walk the target
// monotonically in the given direction (otherwise the segments cannot be paired).
bool pairs_in_order(const ArcCurve& target, const Vector& on_target, int direction) {
  const Index k = on_target.size();
  if (target.closed()) {
    double previous = 0.0;
    for (Index j = 1; j < k; ++j) {
      const double d = direction > 0 ? target.forward(on_target[0], on_target[j])
                                     : target.forward(on_target[j], on_target[0]);
      if (!(d > previous)) return false;
      previous = d;
    }
    return true;
  }
  for (Index j = 1; j < k; ++j) {
    if (!(on_target[j] > on_target[j - 1])) return false;
  }
  return true;
}

// Stacks the vectors of all jobs in the order of their keys (arc position of the start along the
// source; the reverse-diffusion vectors of "auto" fall in among the others).
Vectors gather(std::vector<Vectors>& parts) {
  Index total = 0;
  for (const Vectors& v : parts) total += v.starts.rows();
  std::vector<std::pair<std::size_t, Index>> order;
  order.reserve(total);
  for (std::size_t p = 0; p < parts.size(); ++p) {
    for (Index i = 0; i < parts[p].starts.rows(); ++i) order.emplace_back(p, i);
  }
  std::stable_sort(order.begin(), order.end(), [&](const auto& a, const auto& b) {
    return parts[a.first].keys[a.second] < parts[b.first].keys[b.second];
  });
  Vectors all;
  all.starts.resize(total, 2);
  all.ends.resize(total, 2);
  for (Index r = 0; r < total; ++r) {
    const Vectors& v = parts[order[r].first];
    all.starts.row(r) = v.starts.row(order[r].second);
    all.ends.row(r) = v.ends.row(order[r].second);
    all.methods.push_back(v.methods[order[r].second]);
  }
  return all;
}

Vectors map_directed(const Points2& source_points, const Points2& target_points, MapMethod method,
                     bool closed, bool split, const std::optional<std::pair<Vec2, Vec2>>& anchors,
                     double density_threshold) {
  const ArcCurve source(source_points, closed, "c1");
  const ArcCurve target(target_points, closed, "c2");
  const Index n = source.size();
  const bool wants_normals = method == MapMethod::normal || method == MapMethod::automatic;
  const Points2 source_normals = wants_normals ? normals(source.points(), closed) : Points2();
  const int direction = closed && (split || method == MapMethod::uniform)
                            ? relative_direction(source, target)
                            : 1;

  CurveIntersections crossings;
  if (split || (closed && method == MapMethod::uniform)) {
    crossings = curve_intersections(source.points(), target.points(), closed);
  }
  const Index k = crossings.points.rows();
  const bool pieces = split && k > 0 && pairs_in_order(target, crossings.arc_lengths2, direction);

  auto add_starts = [&](Job& job, const std::vector<Index>& points, Index first_row) {
    for (std::size_t j = 0; j < points.size(); ++j) job.start_rows.push_back(first_row + j);
    if (wants_normals) {
      job.normals.resize(points.size(), 2);
      for (std::size_t j = 0; j < points.size(); ++j) job.normals.row(j) = source_normals.row(points[j]);
    }
  };

  if (!pieces) {
    Job job;
    job.source = source.points();
    job.source_closed = closed;
    std::vector<Index> all(n);
    std::vector<double> keys(n);
    for (Index i = 0; i < n; ++i) all[i] = i, keys[i] = source.arc(i);
    add_starts(job, all, 0);
    job.target = target.points();
    job.target_closed = closed;
    if (method == MapMethod::uniform) {
      double from = 0.0;  // source anchor
      if (!closed) {
        job.anchor = 0.0;
      } else if (k > 0) {
        from = crossings.arc_lengths1[0];
        job.anchor = crossings.arc_lengths2[0];
      } else if (anchors) {
        from = closest_points(anchors->first.transpose(), source.points(), true).arc_lengths[0];
        job.anchor = closest_points(anchors->second.transpose(), target.points(), true).arc_lengths[0];
      } else {
        job.anchor = best_anchor(source, target, direction);
      }
      job.direction = direction;
      job.fractions.resize(n);
      for (Index i = 0; i < n; ++i) job.fractions[i] = source.forward(from, source.arc(i)) / source.length();
    }
    std::vector<Vectors> parts{run(method, job, keys, source, density_threshold)};
    return gather(parts);
  }

  // Split: piece p of the source runs from bound[p] to bound[p + 1] and maps onto the target
  // between target_bound[p] and target_bound[p + 1]; the crossings map onto themselves.
  std::vector<double> bound, target_bound;
  std::vector<char> bound_is_crossing;
  if (!closed) bound.push_back(0.0), target_bound.push_back(0.0), bound_is_crossing.push_back(0);
  for (Index j = 0; j < k; ++j) {
    bound.push_back(crossings.arc_lengths1[j]);
    target_bound.push_back(crossings.arc_lengths2[j]);
    bound_is_crossing.push_back(1);
  }
  if (closed) {
    bound.push_back(crossings.arc_lengths1[0] + source.length());
    target_bound.push_back(crossings.arc_lengths2[0]);
    bound_is_crossing.push_back(1);
  } else {
    bound.push_back(source.length());
    target_bound.push_back(target.length());
    bound_is_crossing.push_back(0);
  }
  const Index piece_count = static_cast<Index>(bound.size()) - 1;
  const std::vector<double> cuts(closed ? bound.begin() : bound.begin() + 1, bound.end() - 1);
  auto crossing_at = [&](Index b) -> Vec2 {  // the crossing that bound b stands for
    return crossings.points.row(closed ? b % k : b - 1).transpose();
  };

  // Each source point goes to the piece it lies in; a point that is (within rounding) a crossing
  // stays where it is, as the crossings do.
  const double coincident = 1e-12 * source.length();
  std::vector<std::vector<Index>> members(piece_count);
  std::vector<Vectors> parts(1);
  Vectors& fixed = parts[0];
  std::vector<Vec2> fixed_points;
  for (Index j = 0; j < k; ++j) {
    fixed_points.push_back(crossings.points.row(j).transpose());
    fixed.keys.push_back(crossings.arc_lengths1[j]);
  }
  for (Index i = 0; i < n; ++i) {
    const double s = source.arc(i);
    const Index after = std::upper_bound(cuts.begin(), cuts.end(), s) - cuts.begin();
    bool on_crossing = false;
    for (Index c : {after - 1, after}) {
      if (c >= 0 && c < k && source.between(s, crossings.arc_lengths1[c]) <= coincident) on_crossing = true;
    }
    if (!on_crossing) members[closed ? (after == 0 ? piece_count - 1 : after - 1) : after].push_back(i);
  }
  fixed.starts.resize(k, 2);
  for (Index j = 0; j < k; ++j) fixed.starts.row(j) = fixed_points[j].transpose();
  fixed.ends = fixed.starts;
  fixed.methods.assign(k, basic_method(method == MapMethod::automatic ? MapMethod::normal : method));

  for (Index p = 0; p < piece_count; ++p) {
    std::vector<Index>& m = members[p];
    if (m.empty()) continue;
    // Along the piece: the closing piece of a closed curve wraps past the first point.
    std::stable_sort(m.begin(), m.end(), [&](Index a, Index b) {
      return source.forward(bound[p], source.arc(a)) < source.forward(bound[p], source.arc(b));
    });
    Job job;
    const Index offset = bound_is_crossing[p] ? 1 : 0;
    job.source.resize(offset + m.size() + (bound_is_crossing[p + 1] ? 1 : 0), 2);
    if (offset) job.source.row(0) = crossing_at(p).transpose();
    for (std::size_t j = 0; j < m.size(); ++j) job.source.row(offset + j) = source.points().row(m[j]);
    if (bound_is_crossing[p + 1]) job.source.row(job.source.rows() - 1) = crossing_at(p + 1).transpose();
    add_starts(job, m, offset);
    const double a = target_bound[p], b = target_bound[p + 1];
    job.target = closed && direction < 0 ? Points2(target.piece(b, a).colwise().reverse()) : target.piece(a, b);
    // The pieces meet exactly at the crossings (the target's are found by arc length).
    if (bound_is_crossing[p]) job.target.row(0) = crossing_at(p).transpose();
    if (bound_is_crossing[p + 1]) job.target.row(job.target.rows() - 1) = crossing_at(p + 1).transpose();
    if (method == MapMethod::uniform) {
      const double length = bound[p + 1] - bound[p];
      job.fractions.resize(m.size());
      for (std::size_t j = 0; j < m.size(); ++j) {
        const double along = closed ? source.forward(bound[p], source.arc(m[j])) : source.arc(m[j]) - bound[p];
        job.fractions[j] = length > 0 ? along / length : 0.0;
      }
    }
    std::vector<double> keys(m.size());
    for (std::size_t j = 0; j < m.size(); ++j) keys[j] = source.arc(m[j]);
    parts.push_back(run(method, job, keys, source, density_threshold));
  }
  return gather(parts);
}

}  // namespace

DisplacementField2 map_curves(const Points2Ref& c1, const Points2Ref& c2,
                              const CurveMappingOptions& options) {
  const bool closed = options.closed;
  const Index n1 = detail::require_curve(c1, closed, "c1");
  const Index n2 = detail::require_curve(c2, closed, "c2");
  if (options.n < 0 || (options.n > 0 && options.n < (closed ? 3 : 2))) {
    detail::invalid("n", "must be 0 (use the given points) or at least " +
                              std::string(closed ? "3" : "2") + ", got " + std::to_string(options.n));
  }
  if (closed) {
    detail::require_area(c1.topRows(n1), "c1");
    detail::require_area(c2.topRows(n2), "c2");
  }
  Points2 a = options.n > 0 ? resample(c1, options.n, closed) : Points2(c1.topRows(n1));
  const Points2 b = options.n > 0 ? resample(c2, options.n, closed) : Points2(c2.topRows(n2));

  Similarity2 similarity;
  if (options.transform) {
    similarity = align_curves(a, b, closed);
    a = similarity.apply(a);
  }
  std::optional<std::pair<Vec2, Vec2>> anchors;
  if (options.anchor) {
    if (!options.anchor->allFinite()) detail::invalid("anchor", "has a non-finite coordinate");
    Points2 anchor = options.anchor->transpose();
    if (options.transform) anchor = similarity.apply(anchor);
    const Vec2 on_c1 = closest_points(anchor, a, closed).points.row(0).transpose();
    const Vec2 on_c2 = closest_points(on_c1.transpose(), b, closed).points.row(0).transpose();
    anchors = options.reverse ? std::make_pair(on_c2, on_c1) : std::make_pair(on_c1, on_c2);
  }

  DisplacementField2 field;
  if (!(options.density_threshold >= 0.0) || !std::isfinite(options.density_threshold)) {
    detail::invalid("density_threshold", "must be a finite number >= 0 (0: off)");
  }
  Vectors v = options.reverse
                  ? map_directed(b, a, options.method, closed, options.split, anchors, options.density_threshold)
                  : map_directed(a, b, options.method, closed, options.split, anchors, options.density_threshold);
  field.starts = std::move(options.reverse ? v.ends : v.starts);
  field.ends = std::move(options.reverse ? v.starts : v.ends);
  // A reverse vector that found no start on C1 is missing as a whole.
  for (Index i = 0; options.reverse && i < field.ends.rows(); ++i) {
    if (!field.valid(i)) field.starts.row(i).setConstant(kNaN), field.ends.row(i).setConstant(kNaN);
  }
  if (options.transform) field.starts = similarity.apply_inverse(field.starts);
  field.methods = std::move(v.methods);
  return field;
}

}  // namespace morphomap
