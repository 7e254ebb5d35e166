// Line intersections and closest points against a triangle surface through Embree: the only file
// that includes Embree. Embree works in single precision, so the triangles are placed in a unit box
// before the scene is built, and every hit is refined in double precision on the original
// triangles afterwards.
#include <morphomap/errors.hpp>
#include <morphomap/surface_queries.hpp>

#include "common/hit_order.hpp"
#include "common/numbers.hpp"
#include "common/validation.hpp"
#include "surfaces/surface_util.hpp"

#include <embree3/rtcore.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace morphomap {

using detail::kInf;
using detail::kNaN;

namespace {

using detail::V3;
constexpr Index kGrain = 64;
// Lines are traced kBlock at a time, one pass per step (forward rays, their refinement, backward
// rays, theirs), so that the memory a step needs is fetched while the step before it still runs.
constexpr int kBlock = 16;
constexpr Index kLineGrain = 16 * kBlock;
// Beyond this many faces the scene's hierarchy no longer stays in the caches, and lines in random
// order spend much of their time waiting for memory: they are then traced in the order of a
// 2^kOrderBits-per-axis Morton grid of their origins, when there are enough of them to share nodes.
// (Lines in mesh-vertex order lose a few percent to this on ~10^5 faces and gain on 10^6.)
constexpr Index kOrderFaces = Index{1} << 16;
constexpr Index kOrderLines = Index{1} << 15;
constexpr int kOrderBits = 6;
// A refined hit whose barycentric coordinates leave its triangle by more than this is looked for
// among the triangles around it (Embree's float test and the double test disagree near edges).
constexpr double kInsideSlack = 1e-12;
// The looser slack of that search, so that a line through an edge or vertex always finds a face.
constexpr double kRingSlack = 1e-9;

// Farthest a closest-point query may lie from the centre, in unit-box lengths, for Embree's float
// scene (a query beyond float range is invalid to it).
constexpr double kReach = 1e30;
// Farthest a line origin may lie from the centre, in unit-box lengths. Embree takes a ray whose
// origin has a coordinate beyond its FLT_LARGE (1.844e18) as invalid, and a build of Embree with
// assertions enabled (Debian's) aborts the process on such a ray.
constexpr double kRayReach = 1e18;

struct Hit {
  V3 point{kNaN, kNaN, kNaN};
  double distance = kNaN;
  Index face = -1;
};

template <class T>
void prefetch(const T* p, bool write = false) {
#if defined(__GNUC__)
  if (write) {
    __builtin_prefetch(p, 1);
  } else {
    __builtin_prefetch(p, 0);
  }
#else
  (void)p, (void)write;
#endif
}

// Whether a hit at signed distance t on `face` comes before `best` (the public order).
bool hit_before(double t, Index face, const Hit& best) {
  return best.face < 0 || detail::line_hit_before(t, face, best.distance, best.face);
}

void store(SurfaceHits& hits, Index i, const Hit& hit) {
  hits.points.row(i) = hit.point.transpose();
  hits.distances[i] = hit.face >= 0 ? hit.distance : kNaN;
  hits.faces[i] = hit.face;
}

}  // namespace

struct SurfaceIndex::Impl {
  Points3 vertices;
  Faces faces;
  V3 centre = V3::Zero();
  double scale = 1.0;                         // unit-box coordinates are (x - centre) * scale
  std::vector<Index> ring_start, ring_faces;  // faces around each vertex (CSR)
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;

  Impl(const Points3Ref& v, const FacesRef& f) : vertices(v), faces(f) {
    detail::require_finite3(vertices, "vertices");
    if (faces.rows() == 0) detail::invalid("faces", "the surface has no face");
    if (faces.rows() >= (Index{1} << 31) || vertices.rows() >= (Index{1} << 31)) {
      detail::invalid("faces", "too many faces or vertices for the index (at most 2^31 - 1)");
    }
    detail::require_face_indices(faces, vertices.rows(), "faces");

    const V3 lo = vertices.colwise().minCoeff().transpose(), hi = vertices.colwise().maxCoeff().transpose();
    centre = 0.5 * (lo + hi);
    const double extent = (hi - lo).maxCoeff();
    scale = extent > 0 ? 1.0 / extent : 1.0;

    ring_start.assign(vertices.rows() + 1, 0);
    for (Index j = 0; j < faces.rows(); ++j) {
      for (int k = 0; k < 3; ++k) ++ring_start[faces(j, k) + 1];
    }
    for (Index i = 0; i < vertices.rows(); ++i) ring_start[i + 1] += ring_start[i];
    ring_faces.resize(ring_start.back());
    std::vector<Index> fill(ring_start.begin(), ring_start.end() - 1);
    for (Index j = 0; j < faces.rows(); ++j) {
      for (int k = 0; k < 3; ++k) ring_faces[fill[faces(j, k)]++] = j;
    }

    device = rtcNewDevice(nullptr);
    if (!device) throw GeometryError("Embree could not create a device");
    scene = rtcNewScene(device);
    // Robust mode makes the triangle test watertight: a ray through a shared edge hits a face.
    // Without it such a ray can pass on to a farther face, which no check of the hit can detect.
    rtcSetSceneFlags(scene, RTC_SCENE_FLAG_ROBUST);
    rtcSetSceneBuildQuality(scene, RTC_BUILD_QUALITY_MEDIUM);
    RTCGeometry geometry = rtcNewGeometry(device, RTC_GEOMETRY_TYPE_TRIANGLE);
    auto* vb = static_cast<float*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT3,
                                                           3 * sizeof(float), vertices.rows()));
    auto* ib = static_cast<unsigned*>(rtcSetNewGeometryBuffer(geometry, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT3,
                                                              3 * sizeof(unsigned), faces.rows()));
    if (!vb || !ib) {
      rtcReleaseGeometry(geometry);
      release();
      throw GeometryError("Embree could not allocate the geometry buffers");
    }
    for (Index i = 0; i < vertices.rows(); ++i) {
      for (int k = 0; k < 3; ++k) vb[3 * i + k] = static_cast<float>((vertices(i, k) - centre[k]) * scale);
    }
    for (Index j = 0; j < faces.rows(); ++j) {
      for (int k = 0; k < 3; ++k) ib[3 * j + k] = static_cast<unsigned>(faces(j, k));
    }
    rtcCommitGeometry(geometry);
    rtcAttachGeometry(scene, geometry);
    rtcReleaseGeometry(geometry);
    rtcCommitScene(scene);
    if (rtcGetDeviceError(device) != RTC_ERROR_NONE) {
      const RTCError error = rtcGetDeviceError(device);
      release();
      throw GeometryError("Embree failed to build the scene (error " + std::to_string(static_cast<int>(error)) + ")");
    }
  }

  ~Impl() { release(); }
  Impl(const Impl&) = delete;
  Impl& operator=(const Impl&) = delete;

  void release() {
    if (scene) rtcReleaseScene(scene), scene = nullptr;
    if (device) rtcReleaseDevice(device), device = nullptr;
  }

  V3 corner(Index face, int k) const { return vertices.row(faces(face, k)).transpose(); }

  // The Embree hit `face` of the line o + t u, refined in double precision; when the refined
  // point falls outside that face, the faces around its corners are tried as well.
  void refine(const V3& o, const V3& u, Index face, Hit& best) const {
    double t = 0.0, outside = 0.0;
    if (detail::line_triangle(o, u, corner(face, 0), corner(face, 1), corner(face, 2), kInsideSlack, t, outside)) {
      if (hit_before(t, face, best)) best.distance = t, best.face = face;
      return;
    }
    Hit ring;
    for (int k = 0; k < 3; ++k) {
      const Index v = faces(face, k);
      for (Index r = ring_start[v]; r < ring_start[v + 1]; ++r) {
        const Index g = ring_faces[r];
        if (detail::line_triangle(o, u, corner(g, 0), corner(g, 1), corner(g, 2), kRingSlack, t, outside) &&
            hit_before(t, g, ring)) {
          ring.distance = t, ring.face = g;
        }
      }
    }
    if (ring.face < 0) {
      // Parallel in double, or outside the whole neighbourhood: keep the plane of Embree's face
      // (the float test found the line there, so the point is within rounding of it).
      const V3 a = corner(face, 0), n = (corner(face, 1) - a).cross(corner(face, 2) - a);
      const double denom = n.dot(u);
      if (denom == 0.0 || !(n.squaredNorm() > 0)) return;
      ring.distance = n.dot(a - o) / denom, ring.face = face;
      if (!std::isfinite(ring.distance)) return;
    }
    if (hit_before(ring.distance, ring.face, best)) best = ring;
  }

  // One ray of a line, from the unit-box origin `os` along `dir` up to `tfar`: the face hit or -1.
  Index cast(RTCIntersectContext& context, const V3& os, const V3& dir, float tfar) const {
    RTCRayHit rh;
    rh.ray.org_x = static_cast<float>(os.x()), rh.ray.org_y = static_cast<float>(os.y()),
    rh.ray.org_z = static_cast<float>(os.z());
    rh.ray.dir_x = static_cast<float>(dir.x()), rh.ray.dir_y = static_cast<float>(dir.y()),
    rh.ray.dir_z = static_cast<float>(dir.z());
    rh.ray.tnear = 0.0f;
    rh.ray.tfar = tfar;
    rh.ray.time = 0.0f;
    rh.ray.mask = 0xFFFFFFFFu;
    rh.ray.id = 0;
    rh.ray.flags = 0;
    rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.primID = RTC_INVALID_GEOMETRY_ID;
    rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
    rtcIntersect1(scene, &context, &rh);
    return rh.hit.geomID != RTC_INVALID_GEOMETRY_ID ? static_cast<Index>(rh.hit.primID) : Index{-1};
  }

  // Prefetches the corners of the faces hit (whose rows were prefetched a pass before).
  void fetch_corners(const Index* face, int n) const {
    for (int i = 0; i < n; ++i) {
      if (face[i] < 0) continue;
      for (int k = 0; k < 3; ++k) prefetch(vertices.row(faces(face[i], k)).data());
    }
  }

  // The lines origins.row(r), directions.row(r) for r = order[k] (r = k without an order), k in
  // [begin, end). For each line the forward ray runs to infinity; the backward one only as far as
  // the refined forward hit (plus a float margin), since only a nearer hit can beat it, so Embree
  // prunes most of that second ray. A backward hit as far as the forward one loses the tie anyway
  // (the positive side wins).
  void lines(const Points3Ref& origins, const Points3Ref& directions, const std::uint32_t* order, Index begin,
             Index end, SurfaceHits& hits) const {
    RTCIntersectContext context;
    rtcInitIntersectContext(&context);
    Index row[kBlock], face[kBlock];
    V3 o[kBlock], u[kBlock], os[kBlock];
    Hit best[kBlock];
    for (Index b = begin; b < end; b += kBlock) {
      const int n = static_cast<int>(std::min<Index>(kBlock, end - b));
      if (order) {
        // Rows out of order: fetch the next block's input and output rows while this one runs.
        for (Index k = b + kBlock; k < std::min(end, b + 2 * kBlock); ++k) {
          const Index r = order[k];
          prefetch(origins.row(r).data()), prefetch(directions.row(r).data());
          prefetch(hits.points.row(r).data(), true), prefetch(&hits.distances[r], true);
          prefetch(&hits.faces[r], true);
        }
      }
      for (int i = 0; i < n; ++i) {
        row[i] = order ? static_cast<Index>(order[b + i]) : b + i;
        o[i] = origins.row(row[i]).transpose();
        const V3 d = directions.row(row[i]).transpose();
        u[i] = d / d.stableNorm();
        os[i] = (o[i] - centre) * scale;
        best[i] = Hit{};
      }
      // An origin too far from the surface for Embree (beyond kRayReach unit-box lengths, or past
      // the range of double) would make its ray invalid: such a line is tested against every face
      // in double instead (slow, but only for absurd input).
      bool far[kBlock];
      for (int i = 0; i < n; ++i) {
        far[i] = !(os[i].cwiseAbs().maxCoeff() <= kRayReach);
        if (far[i]) {
          double t = 0.0, outside = 0.0;
          for (Index f = 0; f < faces.rows(); ++f) {
            const bool meets =
                detail::line_triangle(o[i], u[i], corner(f, 0), corner(f, 1), corner(f, 2), kInsideSlack, t, outside);
            if (meets && hit_before(t, f, best[i])) {
              best[i].distance = t, best[i].face = f;
            }
          }
          face[i] = -1;
          continue;
        }
        face[i] = cast(context, os[i], u[i], std::numeric_limits<float>::infinity());
        if (face[i] >= 0) prefetch(faces.row(face[i]).data());
      }
      fetch_corners(face, n);
      for (int i = 0; i < n; ++i) {
        if (face[i] >= 0) refine(o[i], u[i], face[i], best[i]);
      }
      for (int i = 0; i < n; ++i) {
        if (far[i]) continue;
        float tfar = std::numeric_limits<float>::infinity();
        if (best[i].face >= 0) {
          // Unit-box distance of the forward hit, widened by far more than float rounding (of
          // the scene, the origin and Embree's test) can move a hit.
          const double reach = os[i].cwiseAbs().maxCoeff();
          const double bound = std::abs(best[i].distance) * scale * (1.0 + 1e-5) + 1e-5 * (1.0 + reach);
          if (bound < std::numeric_limits<float>::max()) tfar = static_cast<float>(bound);
        }
        face[i] = cast(context, os[i], -u[i], tfar);
        if (face[i] >= 0) prefetch(faces.row(face[i]).data());
      }
      fetch_corners(face, n);
      for (int i = 0; i < n; ++i) {
        if (face[i] >= 0) refine(o[i], u[i], face[i], best[i]);
        if (best[i].face >= 0) best[i].point = o[i] + best[i].distance * u[i];
        store(hits, row[i], best[i]);
      }
    }
  }

  // The lines sorted by the Morton code of their origin's cell in a 2^kOrderBits grid over the
  // unit box (origins outside it are clamped to its border cells); stable within a cell.
  std::vector<std::uint32_t> spatial_order(const Points3Ref& origins) const {
    const Index m = origins.rows();
    constexpr std::uint32_t cells = 1u << kOrderBits;
    std::vector<std::uint32_t> code(m);
    tbb::parallel_for(tbb::blocked_range<Index>(0, m, 4096), [&](const tbb::blocked_range<Index>& range) {
      for (Index i = range.begin(); i < range.end(); ++i) {
        std::uint32_t c = 0;
        for (int k = 0; k < 3; ++k) {
          const double x = ((origins(i, k) - centre[k]) * scale + 0.5) * cells;
          const std::uint32_t q = x <= 0.0                              ? 0u
                                  : x >= static_cast<double>(cells - 1) ? cells - 1
                                                                        : static_cast<std::uint32_t>(x);
          for (int bit = 0; bit < kOrderBits; ++bit) c |= ((q >> bit) & 1u) << (3 * bit + k);
        }
        code[i] = c;
      }
    });
    std::vector<std::uint32_t> start((std::size_t{1} << (3 * kOrderBits)) + 1, 0);
    for (Index i = 0; i < m; ++i) ++start[code[i] + 1];
    for (std::size_t k = 1; k < start.size(); ++k) start[k] += start[k - 1];
    std::vector<std::uint32_t> order(m);
    for (Index i = 0; i < m; ++i) order[start[code[i]]++] = static_cast<std::uint32_t>(i);
    return order;
  }

  struct PointQuery {
    const Impl* self;
    V3 q;
    double margin;  // float rounding of the query and of the scene, in unit-box units
    double best_d2 = kInf;
    Hit hit;
  };

  // Embree calls this for every triangle within the query radius; the distance is measured in
  // double precision on the original triangle and the radius shrunk (with a rounding margin).
  static bool visit(RTCPointQueryFunctionArguments* args) {
    auto* pq = static_cast<PointQuery*>(args->userPtr);
    const Impl& self = *pq->self;
    const Index face = args->primID;
    const V3 p = detail::closest_on_triangle(pq->q, self.corner(face, 0), self.corner(face, 1), self.corner(face, 2));
    const double d2 = (p - pq->q).squaredNorm();
    if (d2 < pq->best_d2 || (d2 == pq->best_d2 && face < pq->hit.face)) {
      pq->best_d2 = d2;
      pq->hit.point = p;
      pq->hit.face = face;
      const float radius = static_cast<float>(std::sqrt(d2) * self.scale * (1.0 + 1e-6) + pq->margin);
      if (radius < args->query->radius) {
        args->query->radius = radius;
        return true;
      }
    }
    return false;
  }

  // Whether q is close enough for the float scene: within 1e30 unit-box lengths of its centre.
  bool within_reach(const V3& q) const { return ((q - centre) * scale).cwiseAbs().maxCoeff() <= kReach; }

  // The closest point within `reach` of q (infinite: anywhere), else no hit. A finite reach is the
  // search's starting radius: far from the surface Embree then skips the whole tree at once, where
  // an unbounded search visits every triangle about as close as the nearest (nested surfaces are
  // almost equidistant over wide patches) before its radius shrinks.
  Hit closest(const V3& q, double reach) const {
    const V3 qs = (q - centre) * scale;
    PointQuery pq{this, q, 1e-6 * (1.0 + qs.cwiseAbs().maxCoeff()), kInf, Hit{}};
    RTCPointQuery query;
    query.x = static_cast<float>(qs.x()), query.y = static_cast<float>(qs.y()), query.z = static_cast<float>(qs.z());
    query.time = 0.0f;
    const double radius = reach * scale * (1.0 + 1e-6) + 2.0 * pq.margin;
    query.radius = radius < 1e30 ? static_cast<float>(radius) : std::numeric_limits<float>::infinity();
    RTCPointQueryContext context;
    rtcInitPointQueryContext(&context);
    rtcPointQuery(scene, &query, &context, &Impl::visit, &pq);
    pq.hit.distance = std::sqrt(pq.best_d2);
    if (!(pq.hit.distance <= reach)) return Hit{};  // the distance as reported, not its square
    return pq.hit;
  }
};

namespace {

SurfaceHits allocate_hits(Index rows) {
  SurfaceHits hits;
  hits.points.resize(rows, 3);
  hits.distances.resize(rows);
  hits.faces.resize(rows);
  return hits;
}

}  // namespace

SurfaceIndex::SurfaceIndex(const Points3Ref& vertices, const FacesRef& faces)
    : impl_(std::make_unique<Impl>(vertices, faces)) {}
SurfaceIndex::~SurfaceIndex() = default;
SurfaceIndex::SurfaceIndex(SurfaceIndex&&) noexcept = default;
SurfaceIndex& SurfaceIndex::operator=(SurfaceIndex&&) noexcept = default;

SurfaceHits SurfaceIndex::closest_points(const Points3Ref& queries) const { return closest_points(queries, kInf); }

SurfaceHits SurfaceIndex::closest_points(const Points3Ref& queries, double max_distance) const {
  detail::require_finite3(queries, "queries");
  if (!(max_distance >= 0.0)) detail::invalid("max_distance", "must be >= 0 (infinity: no limit)");
  // Beyond that, Embree's float query is meaningless, and the double distances overflow.
  for (Index i = 0; i < queries.rows(); ++i) {
    if (!impl_->within_reach(queries.row(i).transpose())) {
      detail::invalid("queries", "row " + std::to_string(i) +
                                     " lies more than 1e30 times the surface's size from it, too far to measure");
    }
  }
  SurfaceHits hits = allocate_hits(queries.rows());
  tbb::parallel_for(tbb::blocked_range<Index>(0, queries.rows(), kGrain), [&](const tbb::blocked_range<Index>& range) {
    for (Index i = range.begin(); i < range.end(); ++i)
      store(hits, i, impl_->closest(queries.row(i).transpose(), max_distance));
  });
  return hits;
}

SurfaceHits SurfaceIndex::line_intersections(const Points3Ref& origins, const Points3Ref& directions) const {
  detail::require_finite3(origins, "origins");
  detail::require_finite3(directions, "directions");
  detail::require_directions(origins, directions);
  SurfaceHits hits = allocate_hits(origins.rows());
  std::vector<std::uint32_t> order;
  if (impl_->faces.rows() >= kOrderFaces && origins.rows() >= kOrderLines && origins.rows() <= Index{UINT32_MAX}) {
    order = impl_->spatial_order(origins);
  }
  const std::uint32_t* ordered = order.empty() ? nullptr : order.data();
  tbb::parallel_for(tbb::blocked_range<Index>(0, origins.rows(), kLineGrain),
                    [&](const tbb::blocked_range<Index>& range) {
                      impl_->lines(origins, directions, ordered, range.begin(), range.end(), hits);
                    });
  return hits;
}

SurfaceHits closest_points(const Points3Ref& queries, const Points3Ref& vertices, const FacesRef& faces) {
  return SurfaceIndex(vertices, faces).closest_points(queries);
}

SurfaceHits line_intersections(const Points3Ref& origins, const Points3Ref& directions, const Points3Ref& vertices,
                               const FacesRef& faces) {
  return SurfaceIndex(vertices, faces).line_intersections(origins, directions);
}

}  // namespace morphomap
