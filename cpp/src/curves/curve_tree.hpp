#pragma once
// The segment tree behind CurveIndex: a bounding-volume hierarchy of one polyline's segments.
// CGAL 5.5's AABB tree is 3D only, and a 2D hierarchy in double precision with ordered traversal
// is small; bench/ measures it against the peers. Line queries walk a float32 copy of its upper
// levels (conservative bounds: the hits themselves are computed in double). Built in
// curve_tree_build.cpp, walked in curve_tree_walk.cpp.
#include <morphomap/curve_queries.hpp>

#include "common/hit_order.hpp"
#include "common/numbers.hpp"
#include "common/simd4.hpp"

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <vector>

namespace morphomap::curve_tree {

using detail::kInf;
using detail::kNaN;

using simd4::F4;

constexpr int kLeafSize = 4;
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

inline std::int64_t leaf_ref(std::int32_t first, std::int32_t count) { return ~(std::int64_t{first} * 8 + count); }

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

inline float float_up(double x) {
  float f = static_cast<float>(x);
  if (static_cast<double>(f) < x) f = std::nextafter(f, std::numeric_limits<float>::infinity());
  return f;
}

// One segment a + s * e, s in [0, 1], stored in leaf order for locality.
struct Segment {
  double ax, ay, ex, ey;
  double start_arc;  // arc length at a
  double length;
  std::int64_t id;  // index in the curve: from point id to point id + 1
};

// A line o + t u with |u| = 1.
struct Line {
  double ox, oy, ux, uy;
};

struct Hit {
  double x = kNaN, y = kNaN, distance = kNaN, s = 0.0;
  const Segment* segment = nullptr;
};

struct Tree {
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

  // Builds the tree (curve_tree_build.cpp) over the first `size` rows of a curve that passed
  // require_curve (which returns that size).
  Tree(const Points2Ref& curve, bool is_closed, Index size);

  // Median split on the longer axis of the centroid box; segments are reordered in place.
  std::int32_t split(std::int32_t begin, std::int32_t end);

  // The oriented box of segments [begin, end) as child k of `nd`: its axis is the principal axis
  // of the end points (along the chord of a curve piece), and it is padded a little so that
  // rounding in the queries' projections cannot put a segment outside it.
  void fit_box(std::int32_t begin, std::int32_t end, Node& nd, int k) const;

  // The float box of segments [begin, end) as child k of line node `nd`, in the normalised frame
  // and along the double box's axis (or x where that overflowed): the axis is rounded to float,
  // then the centre fitted and rounded, then the extents fitted around exactly those and rounded
  // up, with a relative pad for the rounding of the normalised end points and for the leaf
  // test's 1e-12 slack at segment ends.
  void fit_line_box(std::int32_t begin, std::int32_t end, double ux, double uy, LineNode& nd, int k) const;

  // The line leaf of segments [begin, end): groups of four, padded with copies of the last one.
  std::int32_t make_leaf(std::int32_t begin, std::int32_t end);

  // The line node for node `index` of the double tree: the same children, but a child of at most
  // kLineLeaf segments is a line leaf.
  std::int32_t build_lines(std::int64_t index);

  // A node over [begin, end): the range is split (largest part first) into up to four parts;
  // parts of at most kLeafSize segments become leaves, the others nodes of their own.
  std::int64_t build(std::int32_t begin, std::int32_t end);

  // The walks (curve_tree_walk.cpp).

  // Sorts the four (bound, reference) pairs of a node by bound, nearest first, without branches
  // (a sorting network: which children a line or point reaches is unpredictable).
  static void order(double* bound, std::int64_t* ref);

  // Pushes the kept children but the nearest onto the stack, farthest first, and makes the
  // nearest the current one; false when no child is kept.
  static bool descend(double* bound, std::int64_t* ref, int kept, std::int64_t* stack, double* stack_bound, int& top,
                      std::int64_t& current, double& current_bound);

  Hit closest(double qx, double qy) const;

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
  bool start(LineWalk& w, const Line& l) const;

  // One node or leaf of the walk: the float tree culls boxes the line misses and boxes whose
  // nearest |t| exceeds the best hit so far, and orders the rest nearest first; the leaves test
  // the segments in double. False when the walk is over (w.best is the answer).
  bool step(LineWalk& w) const;

  // A line leaf: the segments whose end points are not strictly on one side of the line (in
  // float, with slack, so that no segment the line meets is missed) go on to `visit`. True when
  // the best hit changed.
  bool visit_leaf(std::int32_t code, LineWalk& w) const;

  // Intersection of the line with one segment; keeps it when it beats the best so far. The
  // crossing test needs no division: only an accepted hit divides.
  static void visit(const Segment& s, const Line& l, Hit& best);

  // Every query from all cores: the answers go into rows of `hits` (allocated by the caller).
  void closest_points(const Points2Ref& queries, CurveHits& hits) const;
  void line_intersections(const Points2Ref& origins, const Points2Ref& directions, CurveHits& hits) const;
};

}  // namespace morphomap::curve_tree
