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
constexpr int kStackSize = 128;  // < 32 levels (a child holds at most half its parent) of < 4 pushes

struct Box {
  double lo[2] = {kInf, kInf};
  double hi[2] = {-kInf, -kInf};
  void grow(double x, double y) {
    lo[0] = std::min(lo[0], x), lo[1] = std::min(lo[1], y);
    hi[0] = std::max(hi[0], x), hi[1] = std::max(hi[1], y);
  }
};

// A node of the 4-wide hierarchy: its children's boxes side by side (so that the four box tests
// run together) and their references. A reference >= 0 is an inner node; a leaf is ~(first * 8 +
// count) over the segment arrays; kUnused marks an unused slot (its box is empty).
//
// The boxes are oriented (centre c, unit axis u, half extents hu along u and hv across): a piece
// of a smooth curve of length l fits in a box of width ~ curvature * l^2 / 8, where an axis-aligned
// box is ~ l wide. With axis-aligned boxes a closest-point query at distance d from a curve of n
// segments visits ~ sqrt(n d) leaves, since every leaf within one box width of the answer must be
// opened; with oriented boxes the count no longer grows with n.
constexpr int kWidth = 4;
struct Node {
  double cx[kWidth], cy[kWidth], ux[kWidth], uy[kWidth], hu[kWidth], hv[kWidth];
  std::int64_t child[kWidth];
};
constexpr std::int64_t kUnused = std::numeric_limits<std::int64_t>::max();
static_assert(kLeafSize < 8, "a leaf reference keeps its count in 3 bits");

std::int64_t leaf_ref(std::int32_t first, std::int32_t count) { return ~(std::int64_t{first} * 8 + count); }

// One segment a + s * e, s in [0, 1], stored in leaf order for locality.
struct Segment {
  double ax, ay, ex, ey;
  double start_arc;  // arc length at a
  double length;
  std::int64_t id;   // index in the curve: from point id to point id + 1
};

// A line o + t u with |u| = 1.
struct Line {
  double ox, oy, ux, uy;
};

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
    nodes.reserve(count / kLeafSize + 1);
    build(0, static_cast<std::int32_t>(count));
  }

  // Median split on the longer axis of the centroid box; segments are reordered in place.
  std::int32_t split(std::int32_t begin, std::int32_t end) {
    Box centres;
    for (std::int32_t i = begin; i < end; ++i) {
      const Segment& s = segments[i];
      centres.grow(s.ax + 0.5 * s.ex, s.ay + 0.5 * s.ey);
    }
    const int axis = (centres.hi[0] - centres.lo[0]) >= (centres.hi[1] - centres.lo[1]) ? 0 : 1;
    const std::int32_t middle = begin + (end - begin) / 2;
    std::nth_element(segments.begin() + begin, segments.begin() + middle, segments.begin() + end,
                     [axis](const Segment& a, const Segment& b) {
                       return axis == 0 ? a.ax + 0.5 * a.ex < b.ax + 0.5 * b.ex
                                        : a.ay + 0.5 * a.ey < b.ay + 0.5 * b.ey;
                     });
    return middle;
  }

  // The oriented box of segments [begin, end) as child k of `nd`: its axis is the principal axis
  // of the end points (along the chord of a curve piece), and it is padded a little so that
  // rounding in the queries' projections cannot put a segment outside it.
  void fit_box(std::int32_t begin, std::int32_t end, Node& nd, int k) const {
    double mx = 0.0, my = 0.0;
    for (std::int32_t i = begin; i < end; ++i) {
      const Segment& s = segments[i];
      mx += 2.0 * s.ax + s.ex, my += 2.0 * s.ay + s.ey;
    }
    const double points = 2.0 * (end - begin);
    mx /= points, my /= points;
    double sxx = 0.0, syy = 0.0, sxy = 0.0;
    for (std::int32_t i = begin; i < end; ++i) {
      const Segment& s = segments[i];
      for (const double t : {0.0, 1.0}) {
        const double dx = s.ax + t * s.ex - mx, dy = s.ay + t * s.ey - my;
        sxx += dx * dx, syy += dy * dy, sxy += dx * dy;
      }
    }
    const double angle = 0.5 * std::atan2(2.0 * sxy, sxx - syy);
    const double ux = std::cos(angle), uy = std::sin(angle);
    double lo_u = kInf, hi_u = -kInf, lo_v = kInf, hi_v = -kInf;
    for (std::int32_t i = begin; i < end; ++i) {
      const Segment& s = segments[i];
      for (const double t : {0.0, 1.0}) {
        const double dx = s.ax + t * s.ex - mx, dy = s.ay + t * s.ey - my;
        const double pu = dx * ux + dy * uy, pv = dy * ux - dx * uy;
        lo_u = std::min(lo_u, pu), hi_u = std::max(hi_u, pu);
        lo_v = std::min(lo_v, pv), hi_v = std::max(hi_v, pv);
      }
    }
    const double cu = 0.5 * (lo_u + hi_u), cv = 0.5 * (lo_v + hi_v);
    nd.cx[k] = mx + cu * ux - cv * uy, nd.cy[k] = my + cu * uy + cv * ux;
    nd.ux[k] = ux, nd.uy[k] = uy;
    const double hu = 0.5 * (hi_u - lo_u), hv = 0.5 * (hi_v - lo_v);
    const double pad = 1e-12 * (std::abs(nd.cx[k]) + std::abs(nd.cy[k]) + hu + hv);
    nd.hu[k] = hu + pad, nd.hv[k] = hv + pad;
  }

  // A node over [begin, end): the range is split (largest part first) into up to four parts;
  // parts of at most kLeafSize segments become leaves, the others nodes of their own.
  std::int64_t build(std::int32_t begin, std::int32_t end) {
    const auto index = static_cast<std::int64_t>(nodes.size());
    nodes.push_back({});
    std::int32_t lo[kWidth] = {begin}, hi[kWidth] = {end};
    int parts = 1;
    while (parts < kWidth) {
      int largest = -1;
      for (int k = 0; k < parts; ++k) {
        if (hi[k] - lo[k] > kLeafSize && (largest < 0 || hi[k] - lo[k] > hi[largest] - lo[largest])) largest = k;
      }
      if (largest < 0) break;
      const std::int32_t middle = split(lo[largest], hi[largest]);
      lo[parts] = middle, hi[parts] = hi[largest], hi[largest] = middle;
      ++parts;
    }
    for (int k = 0; k < kWidth; ++k) {
      Node& nd = nodes[index];
      if (k >= parts) {
        nd.cx[k] = nd.cy[k] = nd.uy[k] = nd.hu[k] = nd.hv[k] = 0.0, nd.ux[k] = 1.0, nd.child[k] = kUnused;
        continue;
      }
      fit_box(lo[k], hi[k], nd, k);
      if (hi[k] - lo[k] <= kLeafSize) {
        nd.child[k] = leaf_ref(lo[k], hi[k] - lo[k]);
      } else {
        const std::int64_t child = build(lo[k], hi[k]);  // may move `nodes`
        nodes[index].child[k] = child;
      }
    }
    return index;
  }

  // Sorts the four (bound, reference) pairs of a node by bound, nearest first, without branches
  // (a sorting network: which children a line or point reaches is unpredictable).
  static void order(double* bound, std::int64_t* ref) {
    auto exchange = [bound, ref](int i, int j) {
      const double bi = bound[i], bj = bound[j];
      const std::int64_t ri = ref[i], rj = ref[j];
      const bool swap = bj < bi;
      bound[i] = swap ? bj : bi, bound[j] = swap ? bi : bj;
      ref[i] = swap ? rj : ri, ref[j] = swap ? ri : rj;
    };
    exchange(0, 1), exchange(2, 3), exchange(0, 2), exchange(1, 3), exchange(1, 2);
  }

  // Pushes the kept children but the nearest onto the stack, farthest first, and makes the
  // nearest the current one; false when no child is kept.
  static bool descend(double* bound, std::int64_t* ref, int kept, std::int64_t* stack, double* stack_bound,
                      int& top, std::int64_t& current, double& current_bound) {
    if (kept == 0) return false;
    order(bound, ref);
    for (int k = kept - 1; k > 0; --k) stack[top] = ref[k], stack_bound[top++] = bound[k];
    current = ref[0], current_bound = bound[0];
    return true;
  }

  Hit closest(double qx, double qy) const {
    Hit best;
    double best_d2 = kInf;
    std::int64_t stack[kStackSize];
    double bound[kStackSize];
    int top = 0;
    std::int64_t ref = 0;
    double ref_bound = 0.0;
    for (;;) {
      if (ref_bound <= best_d2) {
        if (ref < 0) {
          const std::int64_t code = ~ref;
          const auto first = static_cast<std::int32_t>(code >> 3), count = static_cast<std::int32_t>(code & 7);
          for (std::int32_t k = first; k < first + count; ++k) {
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
          const Node& nd = nodes[ref];
          double d2[kWidth];  // squared distances to the four boxes
          for (int k = 0; k < kWidth; ++k) {
            const double px = qx - nd.cx[k], py = qy - nd.cy[k];
            const double du = std::max(std::abs(px * nd.ux[k] + py * nd.uy[k]) - nd.hu[k], 0.0);
            const double dv = std::max(std::abs(py * nd.ux[k] - px * nd.uy[k]) - nd.hv[k], 0.0);
            d2[k] = du * du + dv * dv;
          }
          std::int64_t child[kWidth];
          int kept = 0;
          for (int k = 0; k < kWidth; ++k) {
            const bool keep = d2[k] <= best_d2 && nd.child[k] != kUnused;
            kept += keep;
            d2[k] = keep ? d2[k] : kInf;
            child[k] = nd.child[k];
          }
          if (descend(d2, child, kept, stack, bound, top, ref, ref_bound)) continue;
        }
      }
      if (top == 0) break;
      --top;
      ref = stack[top], ref_bound = bound[top];
    }
    best.distance = std::sqrt(best_d2);
    return best;
  }

  Hit line(const Line& l) const {
    Hit best;
    std::int64_t stack[kStackSize];
    double bound[kStackSize];
    int top = 0;
    std::int64_t ref = 0;
    double ref_bound = 0.0;
    auto beaten = [&best](double b) { return b == kInf || (best.segment && b > std::abs(best.distance)); };
    for (;;) {
      if (!beaten(ref_bound)) {
        if (ref < 0) {
          const std::int64_t code = ~ref;
          const auto first = static_cast<std::int32_t>(code >> 3), count = static_cast<std::int32_t>(code & 7);
          for (std::int32_t k = first; k < first + count; ++k) visit(segments[k], l, best);
        } else {
          const Node& nd = nodes[ref];
          double b[kWidth];
          for (int k = 0; k < kWidth; ++k) {
            // Smallest |t| of a point of the box on the line, or +inf when the line misses it:
            // the centre's distance from the line against the box's half width across it, with
            // slack for rounding so that a line through a corner of the box cannot miss it.
            // In the box's frame the line's direction is (du, dv).
            const double cx = nd.cx[k] - l.ox, cy = nd.cy[k] - l.oy;
            const double du = std::abs(l.ux * nd.ux[k] + l.uy * nd.uy[k]);
            const double dv = std::abs(l.uy * nd.ux[k] - l.ux * nd.uy[k]);
            const double across = std::abs(l.ux * cy - l.uy * cx);
            const double slack = 1e-12 * (std::abs(cx) + std::abs(cy) + nd.hu[k] + nd.hv[k]);
            const double along = l.ux * cx + l.uy * cy, reach = du * nd.hu[k] + dv * nd.hv[k];
            const double near = std::max(std::abs(along) - reach, 0.0);
            b[k] = across > dv * nd.hu[k] + du * nd.hv[k] + slack ? kInf : near;
          }
          // Not beaten (see `beaten`: a NaN bound is not beaten).
          const double limit = best.segment ? std::abs(best.distance) : kInf;
          std::int64_t child[kWidth];
          int kept = 0;
          for (int k = 0; k < kWidth; ++k) {
            const bool keep = b[k] != kInf && !(b[k] > limit) && nd.child[k] != kUnused;
            kept += keep;
            // A NaN bound (overflowing boxes) is never beaten, like 0, which also sorts.
            b[k] = keep ? (b[k] == b[k] ? b[k] : 0.0) : kInf;
            child[k] = nd.child[k];
          }
          if (descend(b, child, kept, stack, bound, top, ref, ref_bound)) continue;
        }
      }
      if (top == 0) break;
      --top;
      ref = stack[top], ref_bound = bound[top];
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
                        store(hits, i, impl_->line({origins(i, 0), origins(i, 1), ux, uy}));
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
