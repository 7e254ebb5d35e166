// The trace stage of 3D diffusion: the streamlines of the recovered gradient of c, from the
// corners of the mesh's source facets (or from each source vertex), and each vertex's exit.
#include "diffusion/shell_tracer.hpp"

#include <morphomap/surface_queries.hpp>

#include "common/interrupt_check.hpp"
#include "common/mesh_adjacency.hpp"
#include "common/numbers.hpp"
#include "diffusion/dirichlet.hpp"

#include <tbb/parallel_for.h>
#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <utility>
#include <vector>

namespace morphomap {

using detail::kNaN;

namespace {

using Vec3 = Eigen::Vector3d;
using Vec4 = Eigen::Vector4d;
using detail::crossing_vertex;
using detail::source_vertex;
using detail::target_vertex;

// Follows -grad c from the source boundary of the mesh to its target boundary. As in 2D, the P1
// gradient (constant on each tetrahedron) is recovered at the vertices as the volume-weighted mean
// over the tetrahedra around each, and normal to the surface at its Dirichlet vertices; that field
// is interpolated linearly and integrated with RK4 steps of a fraction of the local element size,
// each step followed as a straight segment from tetrahedron to tetrahedron until it stays inside
// one or leaves the mesh through a face of the target.
class Tracer {
 public:
  Tracer(const detail::ShellMesh& mesh, const Vector& c, const std::vector<char>& kind) : mesh_(mesh), c_(c) {
    const Index n = mesh.vertices.rows(), tets = mesh.tetrahedra.rows();
    velocity_.assign(n, Vec3::Zero());
    std::vector<double> weight(n, 0.0);
    std::vector<Vec3> normal(n, Vec3::Zero());
    step_.resize(tets);
    // Where the surfaces cross, c jumps from 1 to 0 along a curve and no smooth fit holds: in the
    // tetrahedra at such a curve the flow is the element's own -grad c (the P1 field), which
    // points away from the source faces and out through the target faces. NaN elsewhere.
    element_flow_.assign(tets, Vec3::Constant(kNaN));
    gradients_.resize(static_cast<std::size_t>(tets));
    for (Index t = 0; t < tets; ++t) {
      Eigen::Matrix<double, 4, 3>& g = gradients_[static_cast<std::size_t>(t)];
      const double volume = std::abs(detail::tetrahedron_gradients(mesh.vertices, mesh.tetrahedra, t, g));
      Vec3 flow = Vec3::Zero();
      bool at_crossing = false;
      for (int i = 0; i < 4; ++i) {
        flow -= c[mesh.tetrahedra(t, i)] * g.row(i).transpose();
        at_crossing = at_crossing || kind[mesh.tetrahedra(t, i)] == crossing_vertex;
      }
      if (at_crossing) element_flow_[t] = flow;
      double edges = 0.0;
      for (int i = 0; i < 4; ++i) {
        const Index v = mesh.tetrahedra(t, i);
        velocity_[v] += volume * flow;
        weight[v] += volume;
        for (int j = i + 1; j < 4; ++j) edges += (point(v) - point(mesh.tetrahedra(t, j))).norm();
      }
      step_[t] = 0.25 * edges / 6.0;
      for (int i = 0; i < 4; ++i) {
        if (mesh.patches(t, i) != detail::source_face && mesh.patches(t, i) != detail::target_face) continue;
        // Boundary face opposite vertex i: its (unnormalised) normal, the sign does not matter.
        const Index a = mesh.tetrahedra(t, (i + 1) % 4), b = mesh.tetrahedra(t, (i + 2) % 4),
                    d = mesh.tetrahedra(t, (i + 3) % 4);
        Vec3 m = (point(b) - point(a)).cross(point(d) - point(a));
        if (m.dot(point(a) - point(mesh.tetrahedra(t, i))) < 0.0) m = -m;  // outwards
        for (const Index v : {a, b, d}) normal[v] += m;
      }
    }
    for (Index v = 0; v < n; ++v) {
      if (weight[v] > 0.0) velocity_[v] /= weight[v];
    }
    recover_by_least_squares(c);
    for (Index v = 0; v < n; ++v) {
      // On the surfaces c is constant, so the flow is normal to them: into the region at the
      // source (c = 1 is its maximum), out of it at the target. The fit only gives the speed (its
      // sign may be wrong near a crossing curve, where c jumps).
      if ((kind[v] == source_vertex || kind[v] == target_vertex) && normal[v].squaredNorm() > 0.0) {
        const Vec3 outwards = normal[v].normalized();
        const double speed = std::abs(velocity_[v].dot(outwards));
        velocity_[v] = (kind[v] == source_vertex ? -speed : speed) * outwards;
      }
    }
  }

  // From x on the boundary face of tetrahedron t. Returns the exit point on the target boundary
  // of the mesh, or NaN.
  Vec3 trace(Index t, Vec3 x, std::vector<Vec3>* path) const {
    const Vec3 lost(kNaN, kNaN, kNaN);
    if (path) path->push_back(x);
    int stalled = 0;
    for (int step = 0; step < kStepLimit; ++step) {
      if (step % 1024 == 0) detail::check_interrupt();
      const double h = step_[t];
      const Vec3 k1 = direction(t, x);
      if (k1.squaredNorm() == 0.0) return stopped(locate(t, x), x);
      const Vec3 k2 = direction(t, x + 0.5 * h * k1), k3 = direction(t, x + 0.5 * h * k2),
                 k4 = direction(t, x + h * k3);
      const Vec3 y = x + (h / 6.0) * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
      const Vec3 before = x;
      const int outcome = walk(t, x, y);
      if (path) path->push_back(x);
      // Pressed against a boundary that is not the target, a streamline stops moving.
      stalled = x == before ? stalled + 1 : 0;
      if (stalled == kStallLimit) return stopped(t, x);
      if (outcome == reached_target) return x;
      if (outcome == lost_way) return lost;
    }
    return lost;
  }

 private:
  enum Outcome { inside = 0, reached_target = 1, lost_way = 2 };
  static constexpr int kStepLimit = 100000;
  static constexpr int kWalkLimit = 10000;
  static constexpr int kStallLimit = 16;

  Vec3 point(Index v) const { return mesh_.vertices.row(v).transpose(); }

  // Where a streamline that stopped moving at x in tetrahedron t ends: at x if t touches a curve
  // where the surfaces cross (the streamline has run into the curve, a point of the target) or
  // has c = 0 at every corner (it is at the target's level), else nowhere (NaN).
  Vec3 stopped(Index t, const Vec3& x) const {
    bool level_zero = true;
    for (int i = 0; i < 4; ++i) level_zero = level_zero && c_[mesh_.tetrahedra(t, i)] == 0.0;
    if (level_zero || !std::isnan(element_flow_[t].x())) return x;
    return Vec3::Constant(kNaN);
  }

  // The volume-weighted mean of the element gradients is only first-order accurate on an
  // irregular mesh. Better: fit a quadratic to the nodal values around each vertex (its
  // neighbours, and theirs where there are few), weighted by inverse squared distance; its
  // gradient at the vertex is second-order accurate. The mean stays where the fit is singular.
  void recover_by_least_squares(const Vector& c) {
    const Index n = mesh_.vertices.rows();
    const detail::CompressedRows ring = detail::neighbouring_vertices(n, mesh_.tetrahedra);
    const auto ring_of = [&](Index v) {
      return std::make_pair(ring.entries.begin() + ring.first[v], ring.entries.begin() + ring.first[v + 1]);
    };
    tbb::parallel_for(Index(0), n, [&](Index v) {
      const auto [begin, end] = ring_of(v);
      std::vector<Index> patch(begin, end);
      if (patch.size() < 14) {
        for (auto w = begin; w != end; ++w) {
          const auto [from, to] = ring_of(*w);
          patch.insert(patch.end(), from, to);
        }
        std::sort(patch.begin(), patch.end());
        patch.erase(std::unique(patch.begin(), patch.end()), patch.end());
        patch.erase(std::remove(patch.begin(), patch.end(), v), patch.end());
      }
      if (patch.size() < 12) return;
      double h = 0.0;
      for (const Index w : patch) h += (point(w) - point(v)).norm();
      h /= static_cast<double>(patch.size());
      Eigen::Matrix<double, 9, 9> normal_matrix = Eigen::Matrix<double, 9, 9>::Zero();
      Eigen::Matrix<double, 9, 1> rhs = Eigen::Matrix<double, 9, 1>::Zero();
      for (const Index w : patch) {
        const Vec3 d = (point(w) - point(v)) / h;
        const double weight = 1.0 / d.squaredNorm();
        Eigen::Matrix<double, 9, 1> row;
        row << d.x(), d.y(), d.z(), 0.5 * d.x() * d.x(), 0.5 * d.y() * d.y(), 0.5 * d.z() * d.z(), d.x() * d.y(),
            d.y() * d.z(), d.z() * d.x();
        normal_matrix += weight * row * row.transpose();
        rhs += weight * (c[w] - c[v]) * row;
      }
      const Eigen::LDLT<Eigen::Matrix<double, 9, 9>> fit(normal_matrix);
      if (fit.info() != Eigen::Success || !(fit.rcond() > 1e-10)) return;
      const Eigen::Matrix<double, 9, 1> x = fit.solve(rhs);
      if (!x.allFinite()) return;
      velocity_[v] = -x.head<3>() / h;
    });
  }

  // From the gradients of the barycentric coordinates, kept from the constructor: a streamline
  // asks for them about ten times per step, and solving the tetrahedron's 3 x 3 system each time
  // was most of the trace.
  Vec4 barycentric(Index t, const Vec3& x) const {
    Vec4 l = gradients_[static_cast<std::size_t>(t)] * (x - point(mesh_.tetrahedra(t, 0)));
    l[0] += 1.0;
    return l;
  }

  // The tetrahedron containing x, walking from t towards it; the last one reached if x lies
  // outside the mesh (the field is then extrapolated from there).
  // l: x's barycentric coordinates in the tetrahedron returned.
  Index locate(Index t, const Vec3& x, Vec4& l) const {
    for (int k = 0; k < kWalkLimit; ++k) {
      l = barycentric(t, x);
      int i;
      if (l.minCoeff(&i) >= -1e-12) return t;
      const Index next = mesh_.neighbours(t, i);
      if (next < 0) return t;
      t = next;
    }
    l = barycentric(t, x);
    return t;
  }
  Index locate(Index t, const Vec3& x) const {
    Vec4 l;
    return locate(t, x, l);
  }

  Vec3 direction(Index t, const Vec3& x) const {
    Vec4 l;
    t = locate(t, x, l);
    Vec3 u = element_flow_[t];
    if (std::isnan(u.x())) {
      u.setZero();
      for (int i = 0; i < 4; ++i) u += l[i] * velocity_[mesh_.tetrahedra(t, i)];
    }
    const double norm = u.norm();
    return norm > 0.0 ? Vec3(u / norm) : Vec3::Zero();
  }

  // Moves x along the straight segment to y, tetrahedron by tetrahedron. Sliding along a boundary
  // that is not the target (the flow should not point into it but may, by a rounding of the
  // recovered gradient near the source).
  int walk(Index& t, Vec3& x, Vec3 y) const {
    bool slid = false;
    for (int k = 0; k < kWalkLimit; ++k) {
      const Vec4 ly = barycentric(t, y);
      if (ly.minCoeff() >= 0.0) {
        x = y;
        return inside;
      }
      const Vec4 lx = barycentric(t, x);
      int face = -1;
      double first = 2.0;
      for (int i = 0; i < 4; ++i) {
        if (ly[i] >= 0.0) continue;
        const double a = std::max(lx[i], 0.0);
        const double s = a / (a - ly[i]);
        if (s < first || (s == first && face >= 0 && ly[i] < ly[face])) first = s, face = i;
      }
      const Vec3 p = x + first * (y - x);
      const Index next = mesh_.neighbours(t, face);
      if (next >= 0) {
        t = next;
        x = p;
        continue;
      }
      x = p;
      if (mesh_.patches(t, face) == detail::target_face) return reached_target;
      if (slid) return inside;  // stop the step here
      // Slide: the rest of the step projected onto the face's plane.
      const Index a = mesh_.tetrahedra(t, (face + 1) % 4), b = mesh_.tetrahedra(t, (face + 2) % 4),
                  d = mesh_.tetrahedra(t, (face + 3) % 4);
      const Vec3 m = (point(b) - point(a)).cross(point(d) - point(a)).normalized();
      y -= (y - p).dot(m) * m;
      slid = true;
    }
    return lost_way;
  }

  const detail::ShellMesh& mesh_;
  const Vector& c_;
  std::vector<Vec3> velocity_;      // recovered -grad c at the vertices
  std::vector<Vec3> element_flow_;  // -grad c of the tetrahedra at a crossing curve, else NaN
  std::vector<double> step_;        // RK4 step length in each tetrahedron
  // Gradients of each tetrahedron's barycentric coordinates (rows; tetrahedron_gradients).
  std::vector<Eigen::Matrix<double, 4, 3>> gradients_;
};

// The streamlines from the corners of the source facets of the mesh, and the exit of a
// streamline from any point of a facet interpolated linearly from its corners'. Tracing every
// vertex of s1 cost time in proportion to s1's resolution, not the mesh's (50k streamlines at 100k
// faces, from 3k corners), and was less accurate: a streamline from inside a facet starts along a
// blend of its corners' normals, not the surface's, and such exits scatter about the smooth map
// (bench/README.md, "Exits interpolated from the mesh's source corners").
class FacetNodes {
 public:
  FacetNodes(const detail::ShellMesh& mesh, const Faces& facets, const std::vector<Index>& source_facets)
      : facets_(facets), source_facets_(source_facets), vertices_(mesh.vertices) {
    std::vector<Index> node_of(static_cast<std::size_t>(mesh.vertices.rows()), -1);
    corner_nodes_.resize(facets.rows(), 3);
    for (Index k = 0; k < facets.rows(); ++k) {
      for (int j = 0; j < 3; ++j) {
        Index& node = node_of[static_cast<std::size_t>(facets(k, j))];
        if (node < 0) {
          node = static_cast<Index>(facet_of_.size());
          facet_of_.push_back(k);
          vertex_of_.push_back(facets(k, j));
        }
        corner_nodes_(k, j) = node;
      }
    }
  }

  // The exit of each corner of the wanted facets (NaN where its streamline was lost, and at the
  // other corners), traced from the first facet it is a corner of.
  Points3 trace(const Tracer& tracer, const std::vector<char>& wanted_facets) const {
    const Index count = static_cast<Index>(facet_of_.size());
    std::vector<char> wanted(static_cast<std::size_t>(count), 0);
    for (Index k = 0; k < facets_.rows(); ++k) {
      if (!wanted_facets[static_cast<std::size_t>(k)]) continue;
      for (int j = 0; j < 3; ++j) wanted[static_cast<std::size_t>(corner_nodes_(k, j))] = 1;
    }
    Points3 exits = Points3::Constant(count, 3, kNaN);
    tbb::parallel_for(Index(0), count, [&](Index n) {
      const auto node = static_cast<std::size_t>(n);
      if (!wanted[node]) return;
      const Vec3 start = vertices_.row(vertex_of_[node]).transpose();
      exits.row(n) =
          tracer.trace(source_facets_[static_cast<std::size_t>(facet_of_[node])] / 4, start, nullptr).transpose();
    });
    return exits;
  }

  // The exit from x on facet k; NaN where a corner's streamline was lost.
  Vec3 interpolate(const Points3& exits, Index k, const Vec3& x) const {
    const Vec3 a = vertices_.row(facets_(k, 0)).transpose(), b = vertices_.row(facets_(k, 1)).transpose(),
               c = vertices_.row(facets_(k, 2)).transpose();
    const Vec3 e1 = b - a, e2 = c - a, d = x - a;
    const double g11 = e1.dot(e1), g12 = e1.dot(e2), g22 = e2.dot(e2), r1 = d.dot(e1), r2 = d.dot(e2);
    const double det = g11 * g22 - g12 * g12;
    if (!(det > 0.0)) return Vec3::Constant(kNaN);
    const double l1 = (g22 * r1 - g12 * r2) / det, l2 = (g11 * r2 - g12 * r1) / det;
    return (1.0 - l1 - l2) * exits.row(corner_nodes_(k, 0)).transpose() +
           l1 * exits.row(corner_nodes_(k, 1)).transpose() + l2 * exits.row(corner_nodes_(k, 2)).transpose();
  }

 private:
  const Faces& facets_;
  const std::vector<Index>& source_facets_;
  const Points3& vertices_;
  std::vector<Index> facet_of_;   // each corner node: the first facet it is a corner of
  std::vector<Index> vertex_of_;  // and its mesh vertex
  Eigen::Matrix<Index, Eigen::Dynamic, 3, Eigen::RowMajor> corner_nodes_;
};

}  // namespace

detail::ShellExits detail::trace_exits(const ShellMesh& mesh, const Vector& potential, const std::vector<char>& kind,
                                       const std::vector<Index>& source_facets, const Points3Ref& source_vertices,
                                       const Points3& source_region, const LocalDiffusion* local,
                                       bool keep_streamlines) {
  // Start points: the closest point of the mesh's source boundary to each source vertex.
  Faces facets(static_cast<Index>(source_facets.size()), 3);
  for (std::size_t k = 0; k < source_facets.size(); ++k) {
    const Index t = source_facets[k] / 4;
    const int i = static_cast<int>(source_facets[k] % 4);
    for (int j = 1; j < 4; ++j) facets(static_cast<Index>(k), j - 1) = mesh.tetrahedra(t, (i + j) % 4);
  }
  // (A vertex on an edge or corner that several facets share takes the lowest facet, whatever
  // the traversal: SurfaceIndex's tie rule, which keeps the ends repeatable bit for bit.)
  const SurfaceHits starts = SurfaceIndex(mesh.vertices, facets).closest_points(source_region);

  const Tracer tracer(mesh, potential, kind);
  const Index ns = source_vertices.rows();
  Points3 exits(ns, 3);
  // The vertices that get an exit: all of them, or those a local diffusion traces (else NaN).
  const auto wanted = [&](Index i) { return local == nullptr || local->traced[static_cast<std::size_t>(i)] != 0; };
  // Each wanted vertex's exit is interpolated from the streamlines of the corners of its facet
  // (FacetNodes: only the facets that hold such a vertex); where one of those was lost, and when
  // the streamlines are kept, the vertex is traced itself.
  std::vector<char> interpolated(static_cast<std::size_t>(ns), 0);
  if (!keep_streamlines) {
    const FacetNodes nodes(mesh, facets, source_facets);
    std::vector<char> wanted_facets(source_facets.size(), 0);
    for (Index i = 0; i < ns; ++i) {
      if (wanted(i)) wanted_facets[static_cast<std::size_t>(starts.faces[i])] = 1;
    }
    const Points3 node_exits = nodes.trace(tracer, wanted_facets);
    tbb::parallel_for(Index(0), ns, [&](Index i) {
      if (!wanted(i)) return;
      const Vec3 exit = nodes.interpolate(node_exits, starts.faces[i], starts.points.row(i).transpose());
      if (std::isnan(exit.x())) return;
      exits.row(i) = exit.transpose();
      interpolated[static_cast<std::size_t>(i)] = 1;
    });
  }
  std::vector<std::vector<Vec3>> paths(keep_streamlines ? ns : 0);
  tbb::parallel_for(Index(0), ns, [&](Index i) {
    if (interpolated[static_cast<std::size_t>(i)]) return;
    if (!wanted(i)) {
      exits.row(i).setConstant(kNaN);
      return;
    }
    const Index t = source_facets[starts.faces[i]] / 4;
    std::vector<Vec3>* path = keep_streamlines ? &paths[i] : nullptr;
    if (path) path->push_back(source_vertices.row(i).transpose());
    exits.row(i) = tracer.trace(t, starts.points.row(i).transpose(), path).transpose();
  });
  return ShellExits{std::move(exits), std::move(paths)};
}

}  // namespace morphomap
