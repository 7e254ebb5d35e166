// Walking the segment tree: closest points in double, lines through the float levels, many
// queries at once from all cores.
#include "curves/curve_tree.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace morphomap::curve_tree {

namespace {

constexpr Index kGrain = 256;

using simd4::count_trailing_zeros;
using simd4::key_bound;
using simd4::sorted_keys;
using simd4::store4;

void store(CurveHits& hits, Index i, const Hit& hit) {
  hits.points(i, 0) = hit.x;
  hits.points(i, 1) = hit.y;
  hits.distances[i] = hit.segment ? hit.distance : kNaN;
  hits.segments[i] = hit.segment ? hit.segment->id : -1;
  hits.arc_lengths[i] = hit.segment ? hit.segment->start_arc + hit.s * hit.segment->length : kNaN;
}

}  // namespace

// Sorts the four (bound, reference) pairs of a node by bound, nearest first, without branches
// (a sorting network: which children a line or point reaches is unpredictable).
void Tree::order(double* bound, std::int64_t* ref) {
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
bool Tree::descend(double* bound, std::int64_t* ref, int kept, std::int64_t* stack, double* stack_bound, int& top,
                   std::int64_t& current, double& current_bound) {
  if (kept == 0) return false;
  order(bound, ref);
  for (int k = kept - 1; k > 0; --k) stack[top] = ref[k], stack_bound[top++] = bound[k];
  current = ref[0], current_bound = bound[0];
  return true;
}

Hit Tree::closest(double qx, double qy) const {
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

// Starts the walk of a line; false when it misses the curve's box outright (no hit).
bool Tree::start(LineWalk& w, const Line& l) const {
  w.l = l, w.best = Hit{};
  // The line in the normalised frame: n . x' = d with n = (-uy, ux); t' = u . x' - e.
  const double px = (l.ox - centre_x) * scale, py = (l.oy - centre_y) * scale;
  double d = l.ux * py - l.uy * px, e = l.ux * px + l.uy * py;
  float line_slack = std::numeric_limits<float>::infinity();
  if (std::isfinite(d) && std::isfinite(e)) {
    // The curve lies within sqrt(2) of the frame's origin (d is exact to ~1e-16 (|d| + |e|)).
    if (std::abs(d) > 4.0 + 1e-6 * (std::abs(d) + std::abs(e))) return false;
    if (std::abs(e) <= 1e30) line_slack = float_up(kFloatSlack * (std::abs(d) + std::abs(e)));
  }
  if (line_slack == std::numeric_limits<float>::infinity()) d = e = 0.0;  // astronomically far: no culling
  w.ux = F4::all(static_cast<float>(l.ux)), w.uy = F4::all(static_cast<float>(l.uy));
  w.nx = F4::all(static_cast<float>(-l.uy)), w.ny = w.ux;
  w.fd = F4::all(static_cast<float>(d)), w.fe = F4::all(static_cast<float>(e));
  w.fslack = F4::all(line_slack);
  // Bounds (at least FLT_MIN, see sorted_keys) are compared with the best |t|' rounded up and
  // at least 2^-125, above any key of a bound FLT_MIN.
  w.limit = std::numeric_limits<float>::infinity();
  w.limit4 = F4::all(w.limit);
  w.ref = 0, w.top = 0;
  return true;
}

// One node or leaf of the walk: the float tree culls boxes the line misses and boxes whose
// nearest |t| exceeds the best hit so far, and orders the rest nearest first; the leaves test
// the segments in double. False when the walk is over (w.best is the answer).
bool Tree::step(LineWalk& w) const {
  static constexpr int kCount[16] = {0, 1, 1, 2, 1, 2, 2, 3, 1, 2, 2, 3, 2, 3, 3, 4};
  if (w.ref >= 0) {
    const LineNode& nd = line_nodes[w.ref];
    const F4 cx = F4::load(nd.cx), cy = F4::load(nd.cy), ax = F4::load(nd.ax), ay = F4::load(nd.ay);
    const F4 hu = F4::load(nd.hu), hv = F4::load(nd.hv), slack = F4::load(nd.slack) + w.fslack;
    // The line's direction in each box's frame (du along the axis, dv across), the box's
    // half widths across the line and along it, and its centre's offsets.
    const F4 du = abs(w.ux * ax + w.uy * ay), dv = abs(w.ux * ay - w.uy * ax);
    const F4 across = abs(w.nx * cx + w.ny * cy - w.fd), along = abs(w.ux * cx + w.uy * cy - w.fe);
    const F4 bound = max(along - (du * hu + dv * hv + slack), F4::all(std::numeric_limits<float>::min()));
    const F4 keep = le(across, dv * hu + du * hv + slack) & le(bound, w.limit4);
    const int mask = bits(keep);
    if (mask != 0) {
      // All four keys, farthest first, go on the stack with this node's index; the top moves
      // up by kept - 1, so that the nearest (the last kept) becomes the current reference and
      // the others wait in order; the slots beyond are junk.
      sorted_keys(bound, keep, w.stack_key + w.top);
      store4(w.stack_node + w.top, w.ref);
      w.top += kCount[mask] - 1;
      w.ref = nd.child[w.stack_key[w.top] & 3];
      return true;
    }
  } else if (visit_leaf(~w.ref, w)) {
    w.limit = std::max(float_up(std::abs(w.best.distance) * scale * (1.0 + 1e-9)), 0x1p-125f);
    w.limit4 = F4::all(w.limit);
  }
  do {
    if (w.top == 0) return false;
    --w.top;
  } while (key_bound(w.stack_key[w.top]) > w.limit);
  w.ref = line_nodes[w.stack_node[w.top]].child[w.stack_key[w.top] & 3];
  return true;
}

// A line leaf: the segments whose end points are not strictly on one side of the line (in
// float, with slack, so that no segment the line meets is missed) go on to `visit`. True when
// the best hit changed.
bool Tree::visit_leaf(std::int32_t code, LineWalk& w) const {
  const Segment* before = w.best.segment;
  const Group* group = &groups[code >> 3];
  const int count = (code & 7) + 1;
  unsigned candidates = 0;
  for (int g = 0; g < count; ++g) {
    const Group& gr = group[g];
    const F4 sa = w.nx * F4::load(gr.ax) + w.ny * F4::load(gr.ay) - w.fd;
    const F4 sb = w.nx * F4::load(gr.bx) + w.ny * F4::load(gr.by) - w.fd;
    const F4 slack = F4::load(gr.slack) + w.fslack;
    // min(sa, sb) <= slack and max(sa, sb) >= -slack
    const F4 zero = F4::all(0.0f);
    const F4 near_side = le(sa, slack) | le(sb, slack), far_side = le(zero - sa, slack) | le(zero - sb, slack);
    candidates |= static_cast<unsigned>(bits(near_side & far_side)) << (4 * g);
  }
  while (candidates != 0) {
    const int k = count_trailing_zeros(candidates);
    candidates &= candidates - 1;
    visit(segments[group[k >> 2].segment[k & 3]], w.l, w.best);
  }
  return w.best.segment != before;
}

// Intersection of the line with one segment; keeps it when it beats the best so far. The
// crossing test needs no division: only an accepted hit divides.
void Tree::visit(const Segment& s, const Line& l, Hit& best) {
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
    if ((!best.segment || detail::line_hit_before(t, s.id, best.distance, best.segment->id))) {
      best.x = s.ax + sp * s.ex, best.y = s.ay + sp * s.ey;
      best.distance = t, best.s = sp, best.segment = &s;
    }
    return;
  }
  // Parallel: only a segment lying on the line meets it, along the interval [t0, t1] of t;
  // its point nearest to the origin is the origin itself or an end.
  if (ux * wy - uy * wx != 0.0) return;
  const double t0 = ux * wx + uy * wy, t1 = t0 + ux * s.ex + uy * s.ey;
  const double t = std::min(t0, t1) > 0.0 ? std::min(t0, t1) : std::max(t0, t1) < 0.0 ? std::max(t0, t1) : 0.0;
  const double sp = t1 != t0 ? (t - t0) / (t1 - t0) : 0.0;
  if ((!best.segment || detail::line_hit_before(t, s.id, best.distance, best.segment->id))) {
    best.x = s.ax + sp * s.ex, best.y = s.ay + sp * s.ey;
    best.distance = t, best.s = sp, best.segment = &s;
  }
}

void Tree::closest_points(const Points2Ref& queries, CurveHits& hits) const {
  tbb::parallel_for(tbb::blocked_range<Index>(0, queries.rows(), kGrain), [&](const tbb::blocked_range<Index>& range) {
    for (Index i = range.begin(); i < range.end(); ++i) {
      store(hits, i, closest(queries(i, 0), queries(i, 1)));
    }
  });
}

void Tree::line_intersections(const Points2Ref& origins, const Points2Ref& directions, CurveHits& hits) const {
  tbb::parallel_for(tbb::blocked_range<Index>(0, origins.rows(), kGrain), [&](const tbb::blocked_range<Index>& range) {
    // kWalks lines at a time, each slot refilled with the next line as its
    // walk ends.
    constexpr int kWalks = 4;
    LineWalk walk[kWalks];
    Index which[kWalks];
    bool live[kWalks];
    Index next = range.begin();
    auto refill = [&](int k) {
      while (next < range.end()) {
        const Index i = next++;
        const double dx = directions(i, 0), dy = directions(i, 1);
        const double norm = std::sqrt(dx * dx + dy * dy);
        if (start(walk[k], {origins(i, 0), origins(i, 1), dx / norm, dy / norm})) {
          which[k] = i;
          return true;
        }
        store(hits, i, walk[k].best);
      }
      return false;
    };
    int running = 0;
    for (int k = 0; k < kWalks; ++k) running += live[k] = refill(k);
    while (running > 0) {
      for (int k = 0; k < kWalks; ++k) {
        if (live[k] && !step(walk[k])) {
          store(hits, which[k], walk[k].best);
          running -= !(live[k] = refill(k));
        }
      }
    }
  });
}

}  // namespace morphomap::curve_tree
