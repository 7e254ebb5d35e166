// Surface queries and mapping on spheres and ellipsoids, against brute force and closed forms.
#include <morphomap/morphomap.hpp>

#include <Eigen/Geometry>

#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <random>
#include <stdexcept>
#include <string>
#include <utility>
#include <vector>

#include "check.hpp"

using namespace morphomap;

namespace {

struct Mesh {
  Points3 vertices;
  Faces faces;
};

// An octahedron subdivided `levels` times and pushed onto the unit sphere; outward faces.
Mesh unit_sphere(int levels) {
  std::vector<Eigen::Vector3d> v = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
  std::vector<std::array<Index, 3>> f = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4},
                                         {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  for (int l = 0; l < levels; ++l) {
    std::map<std::pair<Index, Index>, Index> middle;
    auto mid = [&](Index a, Index b) {
      const auto key = std::minmax(a, b);
      auto it = middle.find(key);
      if (it != middle.end()) return it->second;
      v.push_back((v[a] + v[b]).normalized());
      return middle[key] = static_cast<Index>(v.size()) - 1;
    };
    std::vector<std::array<Index, 3>> next;
    for (const auto& t : f) {
      const Index ab = mid(t[0], t[1]), bc = mid(t[1], t[2]), ca = mid(t[2], t[0]);
      next.push_back({t[0], ab, ca});
      next.push_back({ab, t[1], bc});
      next.push_back({ca, bc, t[2]});
      next.push_back({ab, bc, ca});
    }
    f = std::move(next);
  }
  Mesh m;
  m.vertices.resize(v.size(), 3);
  for (std::size_t i = 0; i < v.size(); ++i) m.vertices.row(i) = v[i].normalized().transpose();
  m.faces.resize(f.size(), 3);
  for (std::size_t j = 0; j < f.size(); ++j) m.faces.row(j) << f[j][0], f[j][1], f[j][2];
  return m;
}

Mesh scaled(Mesh m, double a, double b, double c) {
  m.vertices.col(0) *= a, m.vertices.col(1) *= b, m.vertices.col(2) *= c;
  return m;
}

// Nearest intersection of a line with any triangle, by testing all of them.
double brute_line(const Mesh& m, const Eigen::Vector3d& o, const Eigen::Vector3d& u) {
  double best = std::numeric_limits<double>::quiet_NaN();
  for (Index j = 0; j < m.faces.rows(); ++j) {
    const Eigen::Vector3d a = m.vertices.row(m.faces(j, 0)), b = m.vertices.row(m.faces(j, 1)),
                          c = m.vertices.row(m.faces(j, 2));
    const Eigen::Vector3d e1 = b - a, e2 = c - a, p = u.cross(e2);
    const double det = e1.dot(p);
    if (det == 0) continue;
    const Eigen::Vector3d s = o - a, q = s.cross(e1);
    const double bu = s.dot(p) / det, bv = u.dot(q) / det, t = e2.dot(q) / det;
    if (bu < 0 || bv < 0 || bu + bv > 1) continue;
    if (std::isnan(best) || std::abs(t) < std::abs(best)) best = t;
  }
  return best;
}

}  // namespace

int main() {
  const Mesh sphere = unit_sphere(4);  // 2048 faces
  const Mesh ellipsoid = scaled(unit_sphere(5), 2.0, 1.5, 1.2);

  // Checks of a closed surface.
  CHECK_NEAR(check_closed_surface(sphere.vertices, sphere.faces, "s1"), 4.0 / 3.0 * M_PI, 0.05);
  {
    Faces open = sphere.faces.topRows(sphere.faces.rows() - 1);
    CHECK_THROWS(check_closed_surface(sphere.vertices, open, "s1"), InvalidInput);
    Faces flipped = sphere.faces;
    std::swap(flipped(7, 0), flipped(7, 1));
    CHECK_THROWS(check_closed_surface(sphere.vertices, flipped, "s1"), InvalidInput);
    Points3 nan = sphere.vertices;
    nan(3, 1) = std::nan("");
    CHECK_THROWS(check_closed_surface(nan, sphere.faces, "s1"), InvalidInput);
    Faces out = sphere.faces;
    out(0, 0) = sphere.vertices.rows();
    CHECK_THROWS(check_closed_surface(sphere.vertices, out, "s1"), InvalidInput);
    try {
      check_closed_surface(sphere.vertices, open, "s2");
      CHECK(false);
    } catch (const InvalidInput& e) {
      CHECK(std::string(e.what()).rfind("s2: ", 0) == 0);
    }
    // The array rules name the array as Python's conversions do (the one check on the way).
    try {
      check_closed_surface(nan, sphere.faces, "s1");
      CHECK(false);
    } catch (const InvalidInput& e) {
      CHECK(std::string(e.what()).rfind("s1 vertices: row 3 has a non-finite coordinate", 0) == 0);
    }
    try {
      check_closed_surface(sphere.vertices, out, "s2");
      CHECK(false);
    } catch (const InvalidInput& e) {
      CHECK(std::string(e.what()).rfind("s2 faces: vertex index " + std::to_string(sphere.vertices.rows()), 0) == 0);
    }
  }

  // Vertex normals of the sphere point outwards along the radius.
  const Points3 normals = vertex_normals(sphere.vertices, sphere.faces);
  double worst = 0;
  for (Index i = 0; i < normals.rows(); ++i) worst = std::max(worst, (normals.row(i) - sphere.vertices.row(i)).norm());
  CHECK(worst < 0.02);

  // Lines and closest points against brute force.
  std::mt19937_64 rng(20141);
  std::uniform_real_distribution<double> uniform(-2.5, 2.5);
  std::normal_distribution<double> gauss;
  const Index q = 400;
  Points3 origins(q, 3), directions(q, 3);
  for (Index i = 0; i < q; ++i) {
    origins.row(i) << uniform(rng), uniform(rng), uniform(rng);
    directions.row(i) << gauss(rng), gauss(rng), gauss(rng);
  }
  const SurfaceIndex index(ellipsoid.vertices, ellipsoid.faces);
  const SurfaceHits lines = index.line_intersections(origins, directions);
  int hits = 0;
  for (Index i = 0; i < q; ++i) {
    const Eigen::Vector3d u = directions.row(i).normalized();
    const double expected = brute_line(ellipsoid, origins.row(i), u);
    CHECK(std::isnan(expected) == std::isnan(lines.distances[i]));
    if (!std::isnan(expected)) {
      ++hits;
      CHECK_NEAR(lines.distances[i], expected, 1e-9 * 4.0);
      CHECK(lines.faces[i] >= 0);
    } else {
      CHECK(lines.faces[i] == -1);
    }
  }
  CHECK(hits > q / 4);
  const SurfaceHits near = index.closest_points(origins);
  for (Index i = 0; i < q; ++i) {
    double best = std::numeric_limits<double>::infinity();
    const Index f = near.faces[i];
    CHECK(f >= 0);
    // No vertex is nearer than the point found (tests/test_surface_queries.py compares with brute force).
    for (Index v = 0; v < ellipsoid.vertices.rows(); ++v) {
      best = std::min(best, (ellipsoid.vertices.row(v) - origins.row(i)).norm());
    }
    CHECK(near.distances[i] <= best + 1e-15);
    CHECK_NEAR(near.distances[i], (near.points.row(i) - origins.row(i)).norm(), 1e-14);
  }
  // Within a reach: the unlimited answer where it is that close, bit for bit, else nothing. (The
  // reach is each query's own distance too, so that the bound itself is covered.)
  for (const double reach : {0.0, 0.3, 1.0}) {
    const SurfaceHits within = index.closest_points(origins, reach);
    int found = 0;
    for (Index i = 0; i < q; ++i) {
      if (near.distances[i] <= reach) {
        ++found;
        CHECK(within.faces[i] == near.faces[i] && within.points.row(i) == near.points.row(i) &&
              within.distances[i] == near.distances[i]);
      } else {
        CHECK(within.faces[i] == -1 && std::isnan(within.distances[i]) && std::isnan(within.points(i, 0)));
      }
    }
    CHECK(reach == 0.0 || found > 0);
  }
  for (Index i = 0; i < q; ++i) {
    const SurfaceHits own = index.closest_points(origins.row(i), near.distances[i]);
    CHECK(own.faces[0] == near.faces[i] && own.distances[0] == near.distances[i]);
  }
  CHECK_THROWS(index.closest_points(origins, -1.0), InvalidInput);
  CHECK_THROWS(index.closest_points(origins, std::nan("")), InvalidInput);

  // Mapping the sphere onto the ellipsoid.
  SurfaceMappingOptions options;
  options.method = MapMethod::normal;
  const DisplacementField3 normal =
      map_surfaces(sphere.vertices, sphere.faces, ellipsoid.vertices, ellipsoid.faces, options);
  CHECK(normal.size() == sphere.vertices.rows());
  CHECK(normal.faces == sphere.faces);
  for (Index i = 0; i < normal.size(); ++i) CHECK(normal.valid(i));
  CHECK(count_folds(normal.starts, normal.ends, normal.faces, sphere.vertices, sphere.faces, ellipsoid.vertices,
                    ellipsoid.faces) == 0);
  const SurfaceQuality qn = quality(normal, sphere.vertices, sphere.faces, ellipsoid.vertices, ellipsoid.faces);
  CHECK(qn.folds == 0);
  CHECK(std::isfinite(qn.qm1) && std::isfinite(qn.qm2) && qn.qm1 < 0.5);

  options.method = MapMethod::minimal_distance;
  const DisplacementField3 md =
      map_surfaces(sphere.vertices, sphere.faces, ellipsoid.vertices, ellipsoid.faces, options);
  const SurfaceQuality qmd = quality(md, sphere.vertices, sphere.faces, ellipsoid.vertices, ellipsoid.faces);
  CHECK(qmd.qm1 > qn.qm1);

  // Identity: every vector has zero length, every ratio is one.
  const DisplacementField3 same = map_surfaces(sphere.vertices, sphere.faces, sphere.vertices, sphere.faces, options);
  CHECK_NEAR((same.ends - same.starts).cwiseAbs().maxCoeff(), 0.0, 1e-15);
  const SurfaceQuality qs = quality(same, sphere.vertices, sphere.faces, sphere.vertices, sphere.faces);
  CHECK_NEAR(qs.qm1, 0.0, 1e-24);
  CHECK(std::isnan(qs.qm2));  // every swept volume is zero

  // Reverse: the ellipsoid mapped onto the sphere, carried onto the sphere's vertices: the
  // sphere's rows and faces, every end on the ellipsoid.
  options.method = MapMethod::normal;
  options.reverse = true;
  const DisplacementField3 back =
      map_surfaces(sphere.vertices, sphere.faces, ellipsoid.vertices, ellipsoid.faces, options);
  CHECK(back.size() == sphere.vertices.rows());
  CHECK(back.faces == sphere.faces);
  CHECK(back.starts == sphere.vertices);
  const SurfaceHits on_ellipsoid = closest_points(back.ends, ellipsoid.vertices, ellipsoid.faces);
  CHECK(on_ellipsoid.distances.maxCoeff() < 1e-9);

  // The ellipsoid's normals near its long-axis tips cross before they reach the sphere (radius of
  // curvature 1.2^2 / 2 = 0.72 in the xz plane, 1 to go), so their images there are turned over.
  options.reverse = false;
  const DisplacementField3 inward =
      map_surfaces(ellipsoid.vertices, ellipsoid.faces, sphere.vertices, sphere.faces, options);
  CHECK(count_folds(inward.starts, inward.ends, inward.faces, ellipsoid.vertices, ellipsoid.faces, sphere.vertices,
                    sphere.faces) > 0);

  // Folds against closed forms. An affine map with a positive determinant turns nothing over,
  // however far it tilts the triangles in space.
  {
    const Eigen::Matrix3d a = Eigen::AngleAxisd(2.5, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix() *
                              Eigen::Vector3d(2.0, 0.7, 1.3).asDiagonal();
    const Points3 moved = (sphere.vertices * a.transpose()).rowwise() + Eigen::RowVector3d(5, -1, 2);
    CHECK(count_folds(sphere.vertices, moved, sphere.faces, sphere.vertices, sphere.faces, moved, sphere.faces) == 0);
    // A mirror turns every triangle over (the mirrored surface needs its faces reversed to face out).
    Points3 mirrored = moved;
    mirrored.col(0) *= -1.0;
    Faces reversed = sphere.faces;
    reversed.col(1).swap(reversed.col(2));
    CHECK(count_folds(sphere.vertices, mirrored, sphere.faces, sphere.vertices, sphere.faces, mirrored, reversed) ==
          sphere.faces.rows());
  }
  // Folding the upper half of the sphere down onto the lower (z -> -z where z > 0; the equator runs
  // along edges of this mesh) turns exactly the upper faces over, although many of them are tilted
  // by less than 90 degrees; a miss (NaN) takes the faces around it out of the count.
  {
    Points3 folded = sphere.vertices;
    for (Index i = 0; i < folded.rows(); ++i) folded(i, 2) = -std::abs(folded(i, 2));
    Index upper = 0;
    for (Index j = 0; j < sphere.faces.rows(); ++j) {
      double top = -1.0;
      for (int k = 0; k < 3; ++k) top = std::max(top, sphere.vertices(sphere.faces(j, k), 2));
      if (top > 0) ++upper;
    }
    CHECK(upper == sphere.faces.rows() / 2);
    CHECK(count_folds(sphere.vertices, folded, sphere.faces, sphere.vertices, sphere.faces, sphere.vertices,
                      sphere.faces) == upper);
    folded.row(4).setConstant(std::numeric_limits<double>::quiet_NaN());  // the north pole, on 4 faces
    CHECK(count_folds(sphere.vertices, folded, sphere.faces, sphere.vertices, sphere.faces, sphere.vertices,
                      sphere.faces) == upper - 4);
    Faces out = sphere.faces;
    out(0, 0) = sphere.vertices.rows();
    CHECK_THROWS(
        count_folds(sphere.vertices, folded, out, sphere.vertices, sphere.faces, sphere.vertices, sphere.faces),
        InvalidInput);
    const Faces open = sphere.faces.topRows(sphere.faces.rows() - 1);
    CHECK_THROWS(
        count_folds(sphere.vertices, folded, sphere.faces, sphere.vertices, sphere.faces, sphere.vertices, open),
        InvalidInput);
  }

  // The progress callback hears the stages in order: diffusion's three; auto's normal mapping,
  // then, where normals miss (a big sphere round a small one off its centre), reverse diffusion's.
  {
    const Mesh small = unit_sphere(2), inner = scaled(unit_sphere(2), 0.5, 0.5, 0.5);
    const Mesh big = scaled(unit_sphere(2), 3.0, 3.0, 3.0);
    Mesh off = inner;
    off.vertices.col(0).array() += 1.0;
    const Mesh wide = scaled(small, 2.0, 1.5, 1.2);
    std::vector<std::string> stages;
    SurfaceMappingOptions heard;
    heard.on_stage = [&](const char* stage) { stages.emplace_back(stage); };
    const auto run = [&](MapMethod method, const Mesh& a, const Mesh& b, bool reverse) {
      stages.clear();
      heard.method = method;
      heard.reverse = reverse;
      return map_surfaces(a.vertices, a.faces, b.vertices, b.faces, heard);
    };
    run(MapMethod::diffusion, small, wide, false);
    CHECK((stages == std::vector<std::string>{"mesh", "solve", "trace"}));
    run(MapMethod::diffusion, small, wide, true);
    CHECK((stages == std::vector<std::string>{"mesh", "solve", "trace"}));
    run(MapMethod::automatic, small, wide, false);  // normals of a sphere reach an ellipsoid round it
    CHECK((stages == std::vector<std::string>{"normal"}));
    const DisplacementField3 fallback = run(MapMethod::automatic, big, off, false);
    CHECK(fallback.methods.front() == Method::reverse_diffusion);
    CHECK((stages == std::vector<std::string>{"normal", "mesh", "solve", "trace"}));
    run(MapMethod::normal, small, wide, false);
    CHECK(stages.empty());
    // An exception thrown by the callback leaves the call, and the next call runs as usual.
    heard.on_stage = [](const char*) { throw std::runtime_error("stop"); };
    CHECK_THROWS(run(MapMethod::diffusion, small, wide, false), std::runtime_error);
    heard.on_stage = nullptr;
    CHECK(run(MapMethod::diffusion, small, wide, false).ends.allFinite());
  }

  // Prepared surfaces (checked and indexed once) give the same fields and quality, bit for bit.
  {
    const PreparedSurface s1(sphere.vertices, sphere.faces, "frame 1"),
        s2(ellipsoid.vertices, ellipsoid.faces, "frame 2");
    const auto identical = [](const Points3& a, const Points3& b) {  // NaN where the other is NaN
      return a.rows() == b.rows() && ((a.array() == b.array()) || (a.array().isNaN() && b.array().isNaN())).all();
    };
    for (const MapMethod method : {MapMethod::normal, MapMethod::minimal_distance, MapMethod::automatic}) {
      for (const bool reverse : {false, true}) {
        SurfaceMappingOptions same;
        same.method = method;
        same.reverse = reverse;
        const DisplacementField3 plain =
            map_surfaces(sphere.vertices, sphere.faces, ellipsoid.vertices, ellipsoid.faces, same);
        const DisplacementField3 prepared = map_surfaces(s1, s2, same);
        CHECK(identical(prepared.starts, plain.starts) && identical(prepared.ends, plain.ends));
        CHECK(prepared.faces == plain.faces && prepared.methods == plain.methods);
        const SurfaceQuality a = quality(plain, sphere.vertices, sphere.faces, ellipsoid.vertices, ellipsoid.faces);
        const SurfaceQuality b = quality(prepared, s1, s2);
        CHECK(a.qm1 == b.qm1 && a.folds == b.folds);
      }
    }
    const Faces open = sphere.faces.topRows(sphere.faces.rows() - 1);
    try {
      const PreparedSurface bad(sphere.vertices, open, "frames[3]");
      CHECK(false);
    } catch (const InvalidInput& e) {
      CHECK(std::string(e.what()).rfind("frames[3]: ", 0) == 0);
    }
  }

  // Only the table's 3D methods have a 3D form; the refusal names the method and lists them.
  for (const MapMethod method : {MapMethod::uniform, MapMethod::paper}) {
    options.method = method;
    try {
      (void)map_surfaces(sphere.vertices, sphere.faces, ellipsoid.vertices, ellipsoid.faces, options);
      CHECK(false);
    } catch (const InvalidInput& e) {
      CHECK(std::string(e.what()) == std::string("method: ") + map_method_name(method) +
                                         " mapping has no 3D form; use 'auto', 'minimal_distance', 'normal', "
                                         "'diffusion' or 'optimal'");
    }
  }
  TEST_MAIN_END();
}
