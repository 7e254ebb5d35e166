// Building the segment tree: a 4-wide hierarchy of oriented boxes in double, then its float copy
// for line queries.
#include "curves/curve_tree.hpp"

#include "common/validation.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace morphomap::curve_tree {

Tree::Tree(const Points2Ref& curve, bool is_closed, Index size) : points(size), closed(is_closed) {
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
  double lo_x = kInf, lo_y = kInf, hi_x = -kInf, hi_y = -kInf;
  for (const Segment& s : segments) {
    lo_x = std::min(lo_x, s.ax), hi_x = std::max(hi_x, s.ax);
    lo_y = std::min(lo_y, s.ay), hi_y = std::max(hi_y, s.ay);
  }
  if (!closed) lo_x = std::min(lo_x, curve(points - 1, 0)), hi_x = std::max(hi_x, curve(points - 1, 0));
  if (!closed) lo_y = std::min(lo_y, curve(points - 1, 1)), hi_y = std::max(hi_y, curve(points - 1, 1));
  centre_x = 0.5 * lo_x + 0.5 * hi_x, centre_y = 0.5 * lo_y + 0.5 * hi_y;  // no overflow
  const double half = std::max({hi_x - centre_x, centre_x - lo_x, hi_y - centre_y, centre_y - lo_y});
  if (half > 0.0) {
    int exponent = 0;
    std::frexp(half, &exponent);  // half < 2^exponent; a subnormal curve is magnified less
    scale = std::ldexp(1.0, std::min(-exponent, 1000));
  }
  nodes.reserve(count / kLeafSize + 1);
  ranges.reserve(count / kLeafSize + 1);
  build(0, static_cast<std::int32_t>(count));
  line_nodes.reserve(count / kLineLeaf + 1);
  groups.reserve(count / 2 + 1);
  build_lines(0);
  ranges = {};  // only needed to build
}

// Median split on the longer axis of the centroid box; segments are reordered in place.
std::int32_t Tree::split(std::int32_t begin, std::int32_t end) {
  Box centres;
  for (std::int32_t i = begin; i < end; ++i) {
    const Segment& s = segments[i];
    centres.grow(s.ax + 0.5 * s.ex, s.ay + 0.5 * s.ey);
  }
  const int axis = (centres.hi[0] - centres.lo[0]) >= (centres.hi[1] - centres.lo[1]) ? 0 : 1;
  const std::int32_t middle = begin + (end - begin) / 2;
  std::nth_element(segments.begin() + begin, segments.begin() + middle, segments.begin() + end,
                   [axis](const Segment& a, const Segment& b) {
                     return axis == 0 ? a.ax + 0.5 * a.ex < b.ax + 0.5 * b.ex : a.ay + 0.5 * a.ey < b.ay + 0.5 * b.ey;
                   });
  return middle;
}

// The oriented box of segments [begin, end) as child k of `nd`: its axis is the principal axis
// of the end points (along the chord of a curve piece), and it is padded a little so that
// rounding in the queries' projections cannot put a segment outside it.
void Tree::fit_box(std::int32_t begin, std::int32_t end, Node& nd, int k) const {
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

// The float box of segments [begin, end) as child k of line node `nd`, in the normalised frame
// and along the double box's axis (or x where that overflowed): the axis is rounded to float,
// then the centre fitted and rounded, then the extents fitted around exactly those and rounded
// up, with a relative pad for the rounding of the normalised end points and for the leaf
// test's 1e-12 slack at segment ends.
void Tree::fit_line_box(std::int32_t begin, std::int32_t end, double ux, double uy, LineNode& nd, int k) const {
  if (!std::isfinite(ux) || !std::isfinite(uy)) ux = 1.0, uy = 0.0;
  const float fax = static_cast<float>(ux), fay = static_cast<float>(uy);
  const double ax = fax, ay = fay, norm2 = ax * ax + ay * ay;
  auto for_ends = [&](auto f) {  // f(x, y) over the normalised end points
    for (std::int32_t i = begin; i < end; ++i) {
      const Segment& s = segments[i];
      const double px = (s.ax - centre_x) * scale, py = (s.ay - centre_y) * scale;
      f(px, py), f(px + s.ex * scale, py + s.ey * scale);
    }
  };
  double lo_u = kInf, hi_u = -kInf, lo_v = kInf, hi_v = -kInf;
  for_ends([&](double x, double y) {
    const double pu = (x * ax + y * ay) / norm2, pv = (y * ax - x * ay) / norm2;
    lo_u = std::min(lo_u, pu), hi_u = std::max(hi_u, pu), lo_v = std::min(lo_v, pv), hi_v = std::max(hi_v, pv);
  });
  const double cu = 0.5 * (lo_u + hi_u), cv = 0.5 * (lo_v + hi_v);
  const float fcx = static_cast<float>(cu * ax - cv * ay), fcy = static_cast<float>(cu * ay + cv * ax);
  double hu = 0.0, hv = 0.0;
  for_ends([&](double x, double y) {
    const double dx = x - fcx, dy = y - fcy;
    hu = std::max(hu, std::abs(dx * ax + dy * ay) / norm2);
    hv = std::max(hv, std::abs(dy * ax - dx * ay) / norm2);
  });
  const double pad = 1e-6 * (hu + hv) + 1e-14 * (std::abs(fcx) + std::abs(fcy)) + 1e-30;
  nd.cx[k] = fcx, nd.cy[k] = fcy, nd.ax[k] = fax, nd.ay[k] = fay;
  nd.hu[k] = float_up(hu + pad), nd.hv[k] = float_up(hv + pad);
  nd.slack[k] = float_up(kFloatSlack * (std::abs(fcx) + std::abs(fcy) + nd.hu[k] + nd.hv[k]) + 1e-30);
}

// The line leaf of segments [begin, end): groups of four, padded with copies of the last one.
std::int32_t Tree::make_leaf(std::int32_t begin, std::int32_t end) {
  const auto first = static_cast<std::int32_t>(groups.size());
  for (std::int32_t g = begin; g < end; g += 4) {
    Group group;
    for (int k = 0; k < 4; ++k) {
      const std::int32_t i = std::min(g + k, end - 1);
      const Segment& s = segments[i];
      const double ax = (s.ax - centre_x) * scale, ay = (s.ay - centre_y) * scale;
      group.ax[k] = static_cast<float>(ax), group.ay[k] = static_cast<float>(ay);
      group.bx[k] = static_cast<float>(ax + s.ex * scale), group.by[k] = static_cast<float>(ay + s.ey * scale);
      group.slack[k] = float_up(kFloatSlack * std::max(std::abs(group.ax[k]) + std::abs(group.ay[k]),
                                                       std::abs(group.bx[k]) + std::abs(group.by[k])) +
                                1e-30);
      group.segment[k] = i;
    }
    groups.push_back(group);
  }
  const auto count = static_cast<std::int32_t>(groups.size()) - first;
  return ~(first * 8 + count - 1);
}

// The line node for node `index` of the double tree: the same children, but a child of at most
// kLineLeaf segments is a line leaf.
std::int32_t Tree::build_lines(std::int64_t index) {
  const auto line_index = static_cast<std::int32_t>(line_nodes.size());
  line_nodes.push_back({});
  for (int k = 0; k < kWidth; ++k) {
    const Node& nd = nodes[index];
    const std::int32_t lo = ranges[index][2 * k], hi = ranges[index][2 * k + 1];
    LineNode& ln = line_nodes[line_index];
    if (nd.child[k] == kUnused) {
      ln.cx[k] = ln.cy[k] = ln.ay[k] = ln.slack[k] = 0.0f, ln.ax[k] = 1.0f, ln.child[k] = 0;
      ln.hu[k] = ln.hv[k] = std::numeric_limits<float>::quiet_NaN();
      continue;
    }
    fit_line_box(lo, hi, nd.ux[k], nd.uy[k], ln, k);
    // A range of more than kLineLeaf segments is an inner node (kLineLeaf >= kLeafSize).
    const std::int32_t child = hi - lo <= kLineLeaf ? make_leaf(lo, hi) : build_lines(nd.child[k]);
    line_nodes[line_index].child[k] = child;  // build_lines may move `line_nodes`
  }
  return line_index;
}

// A node over [begin, end): the range is split (largest part first) into up to four parts;
// parts of at most kLeafSize segments become leaves, the others nodes of their own.
std::int64_t Tree::build(std::int32_t begin, std::int32_t end) {
  const auto index = static_cast<std::int64_t>(nodes.size());
  nodes.push_back({});
  ranges.push_back({});
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
    ranges[index][2 * k] = lo[k], ranges[index][2 * k + 1] = hi[k];
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

}  // namespace morphomap::curve_tree
