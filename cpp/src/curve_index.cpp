// Closest points and line intersections against one polyline, through a bounding-volume hierarchy
// of its segments. CGAL 5.5's AABB tree is 3D only, and a 2D hierarchy in double precision with
// ordered traversal is small; bench/ measures it against the peers.
#include <morphomap/curve_queries.hpp>

#include "validation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <vector>

namespace morphomap {

namespace {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr int kLeafSize = 4;
constexpr Index kGrain = 256;
constexpr int kStackSize = 96;  // depth of a median-split tree over < 2^31 segments is < 40

struct Box {
  double lo[2] = {kInf, kInf};
  double hi[2] = {-kInf, -kInf};
  void grow(double x, double y) {
    lo[0] = std::min(lo[0], x), lo[1] = std::min(lo[1], y);
    hi[0] = std::max(hi[0], x), hi[1] = std::max(hi[1], y);
  }
};

// A box as centre and half extents: the form the query tests need.
struct CentredBox {
  double cx, cy, hx, hy;
};

// Inner nodes keep their left child right after themselves, so only the right one is stored.
struct Node {
  CentredBox box;
  std::int32_t first;  // leaf: first slot in the segment arrays; inner: index of the right child
  std::int32_t count;  // leaf: number of segments; inner: 0
};

// One segment a + s * e, s in [0, 1], stored in leaf order for locality.
struct Segment {
  double ax, ay, ex, ey;
  double start_arc;  // arc length at a
  double length;
  std::int64_t id;   // index in the curve: from point id to point id + 1
};

double box_distance2(const CentredBox& b, double x, double y) {
  const double dx = std::max(std::abs(x - b.cx) - b.hx, 0.0);
  const double dy = std::max(std::abs(y - b.cy) - b.hy, 0.0);
  return dx * dx + dy * dy;
}

// A line o + t u with |u| = 1, and |u|'s components for the box tests.
struct Line {
  double ox, oy, ux, uy, ax, ay;
};

// Smallest |t| of a point of the box on the line, or +inf when the line misses the box.
double box_line_bound(const CentredBox& b, const Line& l) {
  const double cx = b.cx - l.ox, cy = b.cy - l.oy;
  const double across = std::abs(l.ux * cy - l.uy * cx);  // distance of the centre from the line
  // Slack for rounding: a line through a corner of the box must not miss it.
  const double slack = 1e-12 * (std::abs(cx) + std::abs(cy) + b.hx + b.hy);
  if (across > l.ay * b.hx + l.ax * b.hy + slack) return kInf;
  const double along = l.ux * cx + l.uy * cy, reach = l.ax * b.hx + l.ay * b.hy;
  return std::max(std::abs(along) - reach, 0.0);
}

struct Hit {
  double x = kNaN, y = kNaN, distance = kNaN, s = 0.0;
  const Segment* segment = nullptr;
};

// Order of line hits: nearer the origin first, then the positive side, then the lower segment.
bool line_hit_before(double t, std::int64_t id, const Hit& best) {
  if (!best.segment) return true;
  const double at = std::abs(t), ab = std::abs(best.distance);
  if (at != ab) return at < ab;
  if ((t < 0) != (best.distance < 0)) return t >= 0;
  return id < best.segment->id;
}

}  // namespace

struct CurveIndex::Impl {
  Index points = 0;
  bool closed = true;
  std::vector<Segment> segments;
  std::vector<Node> nodes;

  Impl(const Points2Ref& curve, bool is_closed) : closed(is_closed) {
    points = detail::require_curve(curve, closed, "curve");
    const Index count = closed ? points : points - 1;
    if (count >= std::numeric_limits<std::int32_t>::max()) {
      detail::invalid("curve", "too many points for the index (at most 2^31 - 2 segments)");
    }
    segments.resize(count);
    double arc = 0.0;
    for (Index i = 0; i < count; ++i) {
      const Index j = (i + 1) % points;
      Segment& s = segments[i];
      s.ax = curve(i, 0), s.ay = curve(i, 1);
      s.ex = curve(j, 0) - s.ax, s.ey = curve(j, 1) - s.ay;
      s.length = std::hypot(s.ex, s.ey);
      s.start_arc = arc;
      s.id = i;
      arc += s.length;
    }
    nodes.reserve(2 * (count / kLeafSize + 1));
    build(0, static_cast<std::int32_t>(count));
  }

  // Median split on the longer axis of the centroid box; segments are reordered in place.
  std::int32_t build(std::int32_t begin, std::int32_t end) {
    const auto index = static_cast<std::int32_t>(nodes.size());
    nodes.push_back({});
    Box box, centres;
    for (std::int32_t i = begin; i < end; ++i) {
      const Segment& s = segments[i];
      box.grow(s.ax, s.ay);
      box.grow(s.ax + s.ex, s.ay + s.ey);
      centres.grow(s.ax + 0.5 * s.ex, s.ay + 0.5 * s.ey);
    }
    nodes[index].box = {0.5 * (box.lo[0] + box.hi[0]), 0.5 * (box.lo[1] + box.hi[1]),
                         0.5 * (box.hi[0] - box.lo[0]), 0.5 * (box.hi[1] - box.lo[1])};
    if (end - begin <= kLeafSize) {
      nodes[index].first = begin;
      nodes[index].count = end - begin;
      return index;
    }
    const int axis = (centres.hi[0] - centres.lo[0]) >= (centres.hi[1] - centres.lo[1]) ? 0 : 1;
    const std::int32_t middle = begin + (end - begin) / 2;
    std::nth_element(segments.begin() + begin, segments.begin() + middle, segments.begin() + end,
                     [axis](const Segment& a, const Segment& b) {
                       return axis == 0 ? a.ax + 0.5 * a.ex < b.ax + 0.5 * b.ex
                                        : a.ay + 0.5 * a.ey < b.ay + 0.5 * b.ey;
                     });
    build(begin, middle);
    const std::int32_t right = build(middle, end);
    nodes[index].first = right;
    nodes[index].count = 0;
    return index;
  }

  Hit closest(double qx, double qy) const {
    Hit best;
    double best_d2 = kInf;
    std::int32_t stack[kStackSize];
    double bound[kStackSize];
    int top = 0;
    std::int32_t node = 0;
    double node_bound = 0.0;
    for (;;) {
      if (node_bound <= best_d2) {
        const Node& nd = nodes[node];
        if (nd.count > 0) {
          for (std::int32_t k = nd.first; k < nd.first + nd.count; ++k) {
            const Segment& s = segments[k];
            const double len2 = s.ex * s.ex + s.ey * s.ey;
            double t = len2 > 0 ? ((qx - s.ax) * s.ex + (qy - s.ay) * s.ey) / len2 : 0.0;
            t = std::min(std::max(t, 0.0), 1.0);
            const double px = s.ax + t * s.ex, py = s.ay + t * s.ey;
            const double d2 = (qx - px) * (qx - px) + (qy - py) * (qy - py);
            if (!best.segment || d2 < best_d2 || (d2 == best_d2 && s.id < best.segment->id)) {
              best_d2 = d2;
              best.x = px, best.y = py, best.s = t, best.segment = &s;
            }
          }
        } else {
          std::int32_t near = node + 1, far = nd.first;
          double near_d2 = box_distance2(nodes[near].box, qx, qy);
          double far_d2 = box_distance2(nodes[far].box, qx, qy);
          if (far_d2 < near_d2) std::swap(near, far), std::swap(near_d2, far_d2);
          if (far_d2 <= best_d2) stack[top] = far, bound[top++] = far_d2;
          node = near, node_bound = near_d2;
          continue;
        }
      }
      if (top == 0) break;
      --top;
      node = stack[top], node_bound = bound[top];
    }
    best.distance = std::sqrt(best_d2);
    return best;
  }

  Hit line(const Line& l) const {
    Hit best;
    std::int32_t stack[kStackSize];
    double bound[kStackSize];
    int top = 0;
    std::int32_t node = 0;
    double node_bound = box_line_bound(nodes[0].box, l);
    auto beaten = [&best](double b) { return b == kInf || (best.segment && b > std::abs(best.distance)); };
    for (;;) {
      if (!beaten(node_bound)) {
        const Node& nd = nodes[node];
        if (nd.count > 0) {
          for (std::int32_t k = nd.first; k < nd.first + nd.count; ++k) visit(segments[k], l, best);
        } else {
          std::int32_t near = node + 1, far = nd.first;
          double near_b = box_line_bound(nodes[near].box, l);
          double far_b = box_line_bound(nodes[far].box, l);
          if (far_b < near_b) std::swap(near, far), std::swap(near_b, far_b);
          if (!beaten(far_b)) stack[top] = far, bound[top++] = far_b;
          node = near, node_bound = near_b;
          continue;
        }
      }
      if (top == 0) break;
      --top;
      node = stack[top], node_bound = bound[top];
    }
    return best;
  }

  // Intersection of the line with one segment; keeps it when it beats the best so far. The
  // crossing test needs no division: only an accepted hit divides.
  static void visit(const Segment& s, const Line& l, Hit& best) {
    const double wx = s.ax - l.ox, wy = s.ay - l.oy;
    const double ux = l.ux, uy = l.uy;
    const double denom = ux * s.ey - uy * s.ex;
    if (denom != 0.0) {
      // sp * denom; a little slack so that a line through a vertex cannot slip between the two
      // segments that meet there through rounding.
      const double along = wx * uy - wy * ux;
      const double slack = 1e-12 * std::abs(denom);
      if (denom > 0.0 ? (along < -slack || along > denom + slack) : (along > slack || along < denom - slack)) return;
      const double sp = std::min(std::max(along / denom, 0.0), 1.0);
      const double t = (wx * s.ey - wy * s.ex) / denom;
      if (line_hit_before(t, s.id, best)) {
        best.x = s.ax + sp * s.ex, best.y = s.ay + sp * s.ey;
        best.distance = t, best.s = sp, best.segment = &s;
      }
      return;
    }
    // Parallel: only a segment lying on the line meets it, along the interval [t0, t1] of t;
    // its point nearest to the origin is the origin itself or an end.
    if (ux * wy - uy * wx != 0.0) return;
    const double t0 = ux * wx + uy * wy, t1 = t0 + ux * s.ex + uy * s.ey;
    const double t = std::min(t0, t1) > 0.0   ? std::min(t0, t1)
                     : std::max(t0, t1) < 0.0 ? std::max(t0, t1)
                                              : 0.0;
    const double sp = t1 != t0 ? (t - t0) / (t1 - t0) : 0.0;
    if (line_hit_before(t, s.id, best)) {
      best.x = s.ax + sp * s.ex, best.y = s.ay + sp * s.ey;
      best.distance = t, best.s = sp, best.segment = &s;
    }
  }
};

namespace {

CurveHits allocate_hits(Index rows) {
  CurveHits hits;
  hits.points.resize(rows, 2);
  hits.distances.resize(rows);
  hits.segments.resize(rows);
  hits.arc_lengths.resize(rows);
  return hits;
}

void store(CurveHits& hits, Index i, const Hit& hit) {
  hits.points(i, 0) = hit.x;
  hits.points(i, 1) = hit.y;
  hits.distances[i] = hit.segment ? hit.distance : kNaN;
  hits.segments[i] = hit.segment ? hit.segment->id : -1;
  hits.arc_lengths[i] =
      hit.segment ? hit.segment->start_arc + hit.s * hit.segment->length : kNaN;
}

}  // namespace

CurveIndex::CurveIndex(const Points2Ref& curve, bool closed)
    : impl_(std::make_unique<Impl>(curve, closed)) {}
CurveIndex::~CurveIndex() = default;
CurveIndex::CurveIndex(CurveIndex&&) noexcept = default;
CurveIndex& CurveIndex::operator=(CurveIndex&&) noexcept = default;

Index CurveIndex::size() const { return impl_->points; }
bool CurveIndex::closed() const { return impl_->closed; }

CurveHits CurveIndex::closest_points(const Points2Ref& queries) const {
  detail::require_finite(queries, "queries");
  CurveHits hits = allocate_hits(queries.rows());
  tbb::parallel_for(tbb::blocked_range<Index>(0, queries.rows(), kGrain),
                    [&](const tbb::blocked_range<Index>& range) {
                      for (Index i = range.begin(); i < range.end(); ++i) {
                        store(hits, i, impl_->closest(queries(i, 0), queries(i, 1)));
                      }
                    });
  return hits;
}

CurveHits CurveIndex::line_intersections(const Points2Ref& origins,
                                         const Points2Ref& directions) const {
  detail::require_finite(origins, "origins");
  detail::require_finite(directions, "directions");
  if (origins.rows() != directions.rows()) {
    detail::invalid("directions", "has " + std::to_string(directions.rows()) +
                                      " rows but origins has " + std::to_string(origins.rows()));
  }
  for (Index i = 0; i < directions.rows(); ++i) {
    if (directions(i, 0) == 0.0 && directions(i, 1) == 0.0) {
      detail::invalid("directions", "row " + std::to_string(i) + " is the zero vector");
    }
  }
  CurveHits hits = allocate_hits(origins.rows());
  tbb::parallel_for(tbb::blocked_range<Index>(0, origins.rows(), kGrain),
                    [&](const tbb::blocked_range<Index>& range) {
                      for (Index i = range.begin(); i < range.end(); ++i) {
                        const double dx = directions(i, 0), dy = directions(i, 1);
                        const double norm = std::sqrt(dx * dx + dy * dy);
                        const double ux = dx / norm, uy = dy / norm;
                        store(hits, i, impl_->line({origins(i, 0), origins(i, 1), ux, uy, std::abs(ux), std::abs(uy)}));
                      }
                    });
  return hits;
}

CurveHits closest_points(const Points2Ref& queries, const Points2Ref& curve, bool closed) {
  return CurveIndex(curve, closed).closest_points(queries);
}

CurveHits line_intersections(const Points2Ref& origins, const Points2Ref& directions,
                             const Points2Ref& curve, bool closed) {
  return CurveIndex(curve, closed).line_intersections(origins, directions);
}

}  // namespace morphomap
