// Closest points and line intersections against one polyline, through a bounding-volume hierarchy
// of its segments. CGAL 5.5's AABB tree is 3D only, and a 2D hierarchy in double precision with
// ordered traversal is small; bench/ measures it against the peers. Line queries walk a float32
// copy of its upper levels (conservative bounds: the hits themselves are computed in double).
#include <morphomap/curve_queries.hpp>

#include "validation.hpp"

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#if defined(__SSE2__) || defined(_M_X64)
#include <emmintrin.h>  // SSE2 is part of x86-64: no run-time dispatch needed
#define MORPHOMAP_SSE2 1
#endif

#include <algorithm>
#include <array>
#include <cstring>
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

// The upper levels of the same tree for line queries, with the boxes in float32 and in a
// normalised frame (the curve's bounding box centred on 0 and scaled by a power of 2 into
// [-1, 1]^2), so that a node's four boxes are tested in one SSE register. Each float box contains
// its segments exactly (its extents are fitted around the float centre and axis and rounded
// outward); `slack` is an upper bound, scaled from the box's magnitudes, on the rounding of the
// float test, so the test never culls a box that a line meets. Unused slots have NaN extents,
// which no comparison passes.
// child: an inner line node's index, or a line leaf's code (see Group).
struct alignas(64) LineNode {
  float cx[kWidth], cy[kWidth], ax[kWidth], ay[kWidth], hu[kWidth], hv[kWidth], slack[kWidth];
  std::int32_t child[kWidth];
};
static_assert(sizeof(LineNode) == 128, "two cache lines");

// Four segments of a line leaf side by side, their end points in the normalised frame in float
// (a line leaf holds up to kLineLeaf segments in consecutive groups, the last padded with copies
// of its last segment, which can only tie with it). `slack` bounds the rounding of the float
// sides of the line at the end points, like LineNode::slack. A line leaf's reference is
// ~(first group * 8 + groups - 1).
struct alignas(16) Group {
  float ax[4], ay[4], bx[4], by[4], slack[4];
  std::int32_t segment[4];  // index in `segments`
};
constexpr int kLineLeaf = 16;  // segments; a leaf below a node of four leaves of four, one level less
static_assert(kLineLeaf % 4 == 0 && kLineLeaf / 4 <= 8, "a line leaf's group count takes 3 bits");

// Relative bound on the rounding of the float box test: its terms have a few float roundings
// (2^-24) each and the inputs one more; 4e-6 is ~60 ulps, far above the error, far below a box.
constexpr double kFloatSlack = 4e-6;

float float_up(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

// Four floats: SSE2, or plain arrays where SSE2 is missing. A comparison gives a lane mask.
#ifdef MORPHOMAP_SSE2
struct F4 {
  __m128 v;
  static F4 load(const float* p) { return {_mm_load_ps(p)}; }
  static F4 all(float x) { return {_mm_set1_ps(x)}; }
  friend F4 operator+(F4 a, F4 b) { return {_mm_add_ps(a.v, b.v)}; }
  friend F4 operator-(F4 a, F4 b) { return {_mm_sub_ps(a.v, b.v)}; }
  friend F4 operator*(F4 a, F4 b) { return {_mm_mul_ps(a.v, b.v)}; }
  friend F4 operator&(F4 a, F4 b) { return {_mm_and_ps(a.v, b.v)}; }
  friend F4 operator|(F4 a, F4 b) { return {_mm_or_ps(a.v, b.v)}; }
  friend F4 abs(F4 a) { return {_mm_andnot_ps(_mm_set1_ps(-0.0f), a.v)}; }
  friend F4 max(F4 a, F4 b) { return {_mm_max_ps(a.v, b.v)}; }
  friend F4 le(F4 a, F4 b) { return {_mm_cmple_ps(a.v, b.v)}; }  // false for NaN
  friend int bits(F4 mask) { return _mm_movemask_ps(mask.v); }
};

// The four children as sort keys, farthest first: the bound (at least FLT_MIN, so that no key
// is subnormal, with its last two bits cleared, which only lowers it) with the lane in those
// bits; children not kept get 0, which sorts last. Positive floats order as their bits, so a
// min/max network sorts them (three rounds of two compare-exchanges). Written to out[0..3].
void sorted_keys(F4 bound, F4 keep, std::int32_t* out) {
  const __m128i lane = _mm_set_epi32(3, 2, 1, 0);
  const __m128i low = _mm_set1_epi32(3);
  const __m128i key0 = _mm_castps_si128(bound.v);
  const __m128i key = _mm_and_si128(_mm_castps_si128(keep.v), _mm_or_si128(_mm_andnot_si128(low, key0), lane));
  __m128 k = _mm_castsi128_ps(key);
  // (0 1) (2 3) -> [max01 max23 min01 min23]; again -> [max, ., ., min]; then the middle pair.
  for (int round = 0; round < 2; ++round) {
    const __m128 other = _mm_shuffle_ps(k, k, _MM_SHUFFLE(2, 3, 0, 1));
    k = _mm_shuffle_ps(_mm_max_ps(k, other), _mm_min_ps(k, other), _MM_SHUFFLE(2, 0, 2, 0));
  }
  const __m128 other = _mm_shuffle_ps(k, k, _MM_SHUFFLE(3, 1, 2, 0));
  k = _mm_shuffle_ps(_mm_max_ps(k, other), _mm_min_ps(k, other), _MM_SHUFFLE(3, 2, 1, 0));
  _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm_castps_si128(k));
}

// Four copies of a node index.
void store4(std::int32_t* out, std::int32_t x) {
  _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm_set1_epi32(x));
}
#else
struct F4 {
  float v[4];
  static F4 load(const float* p) { return {{p[0], p[1], p[2], p[3]}}; }
  static F4 all(float x) { return {{x, x, x, x}}; }
  template <class Op> static F4 map(F4 a, F4 b, Op op) {
    return {{op(a.v[0], b.v[0]), op(a.v[1], b.v[1]), op(a.v[2], b.v[2]), op(a.v[3], b.v[3])}};
  }
  friend F4 operator+(F4 a, F4 b) { return map(a, b, [](float x, float y) { return x + y; }); }
  friend F4 operator-(F4 a, F4 b) { return map(a, b, [](float x, float y) { return x - y; }); }
  friend F4 operator*(F4 a, F4 b) { return map(a, b, [](float x, float y) { return x * y; }); }
  friend F4 operator&(F4 a, F4 b) { return map(a, b, [](float x, float y) { return x != 0 && y != 0 ? 1.0f : 0.0f; }); }
  friend F4 operator|(F4 a, F4 b) { return map(a, b, [](float x, float y) { return x != 0 || y != 0 ? 1.0f : 0.0f; }); }
  friend F4 abs(F4 a) { return {{std::abs(a.v[0]), std::abs(a.v[1]), std::abs(a.v[2]), std::abs(a.v[3])}}; }
  friend F4 max(F4 a, F4 b) { return map(a, b, [](float x, float y) { return x > y ? x : y; }); }
  friend F4 le(F4 a, F4 b) { return map(a, b, [](float x, float y) { return x <= y ? 1.0f : 0.0f; }); }
  friend int bits(F4 mask) {
    return (mask.v[0] != 0) | (mask.v[1] != 0) << 1 | (mask.v[2] != 0) << 2 | (mask.v[3] != 0) << 3;
  }
};

void sorted_keys(F4 bound, F4 keep, std::int32_t* out) {
  for (int k = 0; k < 4; ++k) {
    std::memcpy(&out[k], &bound.v[k], sizeof(float));
    out[k] = keep.v[k] != 0 ? (out[k] & ~3) | k : 0;
  }
  std::sort(out, out + 4, [](std::int32_t x, std::int32_t y) { return x > y; });
}

void store4(std::int32_t* out, std::int32_t x) { std::fill(out, out + 4, x); }
#endif

int count_trailing_zeros(unsigned x) {  // x != 0
#if defined(__GNUC__) || defined(__clang__)
  return __builtin_ctz(x);
#else
  int n = 0;
  while (!(x >> n & 1u)) ++n;
  return n;
#endif
}

float key_bound(std::int32_t key) {
  float b;
  std::memcpy(&b, &key, sizeof b);
  return b;
}

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
  // Segment ranges of the children of `nodes` (lo, hi for each), for the line tree.
  std::vector<std::array<std::int32_t, 2 * kWidth>> ranges;
  // Line queries: the same tree in float (LineNode) down to ranges of at most kLineLeaf segments,
  // which become leaves of groups, and the normalised frame x' = (x - centre) * scale with the
  // curve in [-1, 1]^2.
  std::vector<LineNode> line_nodes;
  std::vector<Group> groups;
  double centre_x = 0.0, centre_y = 0.0, scale = 1.0;

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

  // The float box of segments [begin, end) as child k of line node `nd`, in the normalised frame
  // and along the double box's axis (or x where that overflowed): the axis is rounded to float,
  // then the centre fitted and rounded, then the extents fitted around exactly those and rounded
  // up, with a relative pad for the rounding of the normalised end points and for the leaf
  // test's 1e-12 slack at segment ends.
  void fit_line_box(std::int32_t begin, std::int32_t end, double ux, double uy, LineNode& nd, int k) const {
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
  std::int32_t make_leaf(std::int32_t begin, std::int32_t end) {
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
                                                         std::abs(group.bx[k]) + std::abs(group.by[k])) + 1e-30);
        group.segment[k] = i;
      }
      groups.push_back(group);
    }
    const auto count = static_cast<std::int32_t>(groups.size()) - first;
    return ~(first * 8 + count - 1);
  }

  // The line node for node `index` of the double tree: the same children, but a child of at most
  // kLineLeaf segments is a line leaf.
  std::int32_t build_lines(std::int64_t index) {
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
  std::int64_t build(std::int32_t begin, std::int32_t end) {
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

  // One line's walk through the float tree, advanced a node or leaf at a time (`step`), so that a
  // thread can interleave a few lines: one walk is a chain of dependent loads and compares, and
  // the core overlaps independent chains.
  struct LineWalk {
    Line l;
    Hit best;
    F4 ux, uy, nx, ny, fd, fe, fslack, limit4;
    float limit;
    std::int32_t ref;
    int top;
    // Waiting children: their key (bound and lane, see sorted_keys) and their parent's index.
    std::int32_t stack_key[kStackSize], stack_node[kStackSize];
  };

  // Starts the walk of a line; false when it misses the curve's box outright (no hit).
  bool start(LineWalk& w, const Line& l) const {
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
  bool step(LineWalk& w) const {
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
  bool visit_leaf(std::int32_t code, LineWalk& w) const {
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
  const Impl& impl = *impl_;
  tbb::parallel_for(tbb::blocked_range<Index>(0, origins.rows(), kGrain),
                    [&](const tbb::blocked_range<Index>& range) {
                      // kWalks lines at a time, each slot refilled with the next line as its
                      // walk ends.
                      constexpr int kWalks = 4;
                      Impl::LineWalk walk[kWalks];
                      Index which[kWalks];
                      bool live[kWalks];
                      Index next = range.begin();
                      auto refill = [&](int k) {
                        while (next < range.end()) {
                          const Index i = next++;
                          const double dx = directions(i, 0), dy = directions(i, 1);
                          const double norm = std::sqrt(dx * dx + dy * dy);
                          if (impl.start(walk[k], {origins(i, 0), origins(i, 1), dx / norm, dy / norm})) {
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
                          if (live[k] && !impl.step(walk[k])) {
                            store(hits, which[k], walk[k].best);
                            running -= !(live[k] = refill(k));
                          }
                        }
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
