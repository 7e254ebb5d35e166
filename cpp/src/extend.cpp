#include <morphomap/extend.hpp>

#include <morphomap/field_at.hpp>

#include "dirichlet.hpp"
#include "region_mesh.hpp"
#include "validation.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <string>
#include <vector>

namespace morphomap {
namespace {

// The nodes on the mesh's boundary: the corners of the cell faces (edges in 2D, triangles in
// 3D) that only one cell has.
template <class Cells>
std::vector<char> boundary_nodes(const Cells& cells, Index node_count) {
  constexpr int corners = Cells::ColsAtCompileTime;
  using Side = std::array<Index, corners - 1>;
  std::vector<Side> sides;
  sides.reserve(cells.rows() * corners);
  for (Index c = 0; c < cells.rows(); ++c) {
    for (int skip = 0; skip < corners; ++skip) {
      Side side;
      for (int i = 0, k = 0; i < corners; ++i) {
        if (i != skip) side[k++] = cells(c, i);
      }
      std::sort(side.begin(), side.end());
      sides.push_back(side);
    }
  }
  std::sort(sides.begin(), sides.end());
  std::vector<char> on_boundary(node_count, 0);
  for (std::size_t k = 0; k < sides.size();) {
    std::size_t end = k + 1;
    while (end < sides.size() && sides[end] == sides[k]) ++end;
    if (end - k == 1) {
      for (const Index v : sides[k]) on_boundary[v] = 1;
    }
    k = end;
  }
  return on_boundary;
}

template <class Points, class Cells>
void require_mesh(const Points& points, const Cells& cells) {
  if (!points.allFinite()) detail::invalid("mesh", "a point has a non-finite coordinate");
  if (cells.rows() == 0) detail::invalid("mesh", "has no cells");
  for (Index c = 0; c < cells.rows(); ++c) {
    for (Index i = 0; i < cells.cols(); ++i) {
      if (cells(c, i) < 0 || cells(c, i) >= points.rows()) {
        detail::invalid("mesh", "cell " + std::to_string(c) + " refers to point " + std::to_string(cells(c, i)) +
                                    ", outside 0.." + std::to_string(points.rows() - 1));
      }
    }
  }
}

double signed_measure(const Points2& x, const Faces& cells, Index c) {
  const Vec2 a = (x.row(cells(c, 1)) - x.row(cells(c, 0))).transpose(), b = (x.row(cells(c, 2)) - x.row(cells(c, 0))).transpose();
  return 0.5 * (a.x() * b.y() - a.y() * b.x());
}

double signed_measure(const Points3& x, const Tetrahedra& cells, Index c) {
  Eigen::Matrix3d edges;
  for (int i = 0; i < 3; ++i) edges.col(i) = (x.row(cells(c, i + 1)) - x.row(cells(c, 0))).transpose();
  return edges.determinant() / 6.0;
}

// Counts the cells the motion turns over or flattens and the smallest area (volume) ratio.
template <class Interior>
void measure_inversions(Interior& out) {
  const auto moved = (out.points + out.displacement).eval();
  out.inverted = 0;
  out.min_jacobian = std::numeric_limits<double>::infinity();
  for (Index c = 0; c < out.cells.rows(); ++c) {
    const double before = signed_measure(out.points, out.cells, c);
    const double ratio = before != 0 ? signed_measure(moved, out.cells, c) / before : 0.0;
    if (!(ratio > 0)) ++out.inverted;
    out.min_jacobian = std::min(out.min_jacobian, ratio);
  }
}

// The field's displacement at the mesh's boundary nodes (`fixed`; zero elsewhere until solved),
// from project(boundary node positions), and the farthest of those nodes from the boundary.
template <class Interior, class Project>
void take_boundary_values(Interior& out, const std::vector<char>& fixed, const Project& project) {
  using Rows = decltype(out.points);
  std::vector<Index> nodes;
  for (Index v = 0; v < out.points.rows(); ++v) {
    if (fixed[v]) nodes.push_back(v);
  }
  Rows at(nodes.size(), out.points.cols());
  for (std::size_t k = 0; k < nodes.size(); ++k) at.row(k) = out.points.row(nodes[k]);
  const auto boundary = project(at);
  out.displacement = Rows::Zero(out.points.rows(), out.points.cols());
  Index missing = 0;
  for (std::size_t k = 0; k < nodes.size(); ++k) {
    out.displacement.row(nodes[k]) = boundary.displacements.row(k);
    missing += !boundary.displacements.row(k).allFinite();
  }
  if (missing > 0) {
    detail::invalid("field", "has no displacement at " + std::to_string(missing) + " of the " +
                                 std::to_string(nodes.size()) + " boundary nodes (the field has no target there)");
  }
  out.boundary_distance = boundary.distances.size() ? boundary.distances.maxCoeff() : 0.0;
}

template <class Interior, class Local>
void solve_harmonic(Interior& out, const std::vector<char>& fixed, const Local& local, bool iterative) {
  // A flat cell has no gradients: its stiffness would be infinite.
  for (Index c = 0; c < out.cells.rows(); ++c) {
    if (!(std::abs(signed_measure(out.points, out.cells, c)) > 0)) {
      detail::invalid("mesh", "cell " + std::to_string(c) + " is flat (zero " +
                                  (out.cells.cols() == 3 ? "area" : "volume") + ")");
    }
  }
  out.displacement = detail::solve_dirichlet_values(out.points.rows(), out.cells, fixed,
                                                    Eigen::MatrixXd(out.displacement), local, iterative);
  if (!out.displacement.allFinite()) throw GeometryError("the harmonic extension has no finite solution on this mesh");
  measure_inversions(out);
}

}  // namespace

InteriorField2 extend_field(const DisplacementField2& field, const Points2Ref& source, const Points2Ref& mesh_points,
                            const FacesRef& mesh_cells, double mesh_size) {
  detail::require_simple_curve(source, true, "source");
  if (!std::isfinite(mesh_size)) detail::invalid("mesh_size", "must be finite");
  InteriorField2 out;
  if (mesh_cells.rows() == 0) {
    const detail::RegionMesh mesh = detail::mesh_region({detail::without_repeats(source, true, "source")}, mesh_size);
    out.points = mesh.vertices;
    out.cells = mesh.triangles;
  } else {
    require_mesh(mesh_points, mesh_cells);
    out.points = mesh_points;
    out.cells = mesh_cells;
  }
  const std::vector<char> fixed = boundary_nodes(out.cells, out.points.rows());
  take_boundary_values(out, fixed, [&](const Points2& at) { return displacement_at(field, source, true, at); });
  solve_harmonic(out, fixed, [&](Index t) {
    Vec2 p[3];
    for (int i = 0; i < 3; ++i) p[i] = out.points.row(out.cells(t, i)).transpose();
    return detail::triangle_stiffness(p);
  }, false);
  return out;
}

InteriorField3 extend_field(const DisplacementField3& field, const Points3Ref& mesh_points,
                            const TetrahedraRef& mesh_cells) {
  require_mesh(mesh_points, mesh_cells);
  InteriorField3 out;
  out.points = mesh_points;
  out.cells = mesh_cells;
  const std::vector<char> fixed = boundary_nodes(out.cells, out.points.rows());
  take_boundary_values(out, fixed, [&](const Points3& at) { return displacement_at(field, at); });
  solve_harmonic(out, fixed, [&](Index t) {
    Eigen::Matrix<double, 4, 3> g;
    const double volume = std::abs(detail::tetrahedron_gradients(out.points, out.cells, t, g));
    return Eigen::Matrix4d(volume * g * g.transpose());
  }, true);
  return out;
}

}  // namespace morphomap
