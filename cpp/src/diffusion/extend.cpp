#include <morphomap/extend.hpp>

#include <morphomap/field_at.hpp>

#include "common/validation.hpp"
#include "diffusion/dirichlet.hpp"
#include "diffusion/region_mesh.hpp"
#include "diffusion/untangle.hpp"
#include "diffusion/volume_mesh.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace morphomap {
namespace {

// The nodes on the mesh's boundary: the corners of the cell sides (edges in 2D, triangles in
// 3D) that only one cell has. Each side is filed under its smallest corner (a counting sort) as
// one number naming its other corners, so that a side is only compared with the few filed under
// the same node, in parallel by node.
template <class Cells>
std::vector<char> boundary_nodes(const Cells& cells, Index node_count) {
  constexpr int corners = Cells::ColsAtCompileTime;
  using Side = std::array<Index, corners - 1>;
  const Index side_count = cells.rows() * corners;
  const auto side_of = [&](Index s) {
    const Index c = s / corners;
    const int skip = static_cast<int>(s % corners);
    Side side;
    for (int i = 0, k = 0; i < corners; ++i) {
      if (i != skip) side[k++] = cells(c, i);
    }
    std::sort(side.begin(), side.end());
    return side;
  };
  // The corners after the smallest, as one number (node_count^2 fits: node indices are far below 2^31).
  const auto others = [&](const Side& side) {
    Index key = 0;
    for (int k = 1; k < corners - 1; ++k) key = key * node_count + side[k];
    return key;
  };
  std::vector<Index> smallest(side_count), key(side_count);
  tbb::parallel_for(tbb::blocked_range<Index>(0, side_count, 4096), [&](const tbb::blocked_range<Index>& range) {
    for (Index s = range.begin(); s < range.end(); ++s) {
      const Side side = side_of(s);
      smallest[s] = side[0];
      key[s] = others(side);
    }
  });
  std::vector<Index> first(node_count + 1, 0);  // sides filed under node v: first[v] .. first[v + 1]
  for (Index s = 0; s < side_count; ++s) ++first[smallest[s] + 1];
  for (Index v = 0; v < node_count; ++v) first[v + 1] += first[v];
  std::vector<Index> filed(side_count), next(first.begin(), first.end() - 1);
  for (Index s = 0; s < side_count; ++s) filed[next[smallest[s]]++] = key[s];
  // Per node, its sides sorted; a side met twice is inside (both copies set to -1), the rest are on the boundary.
  tbb::parallel_for(tbb::blocked_range<Index>(0, node_count, 1024), [&](const tbb::blocked_range<Index>& range) {
    for (Index v = range.begin(); v < range.end(); ++v) {
      const auto begin = filed.begin() + first[v], end = filed.begin() + first[v + 1];
      std::sort(begin, end);
      for (auto k = begin; k != end;) {
        auto run = k + 1;
        while (run != end && *run == *k) ++run;
        if (run - k > 1) std::fill(k, run, Index(-1));
        k = run;
      }
    }
  });
  std::vector<char> on_boundary(node_count, 0);
  for (Index v = 0; v < node_count; ++v) {
    for (Index k = first[v]; k < first[v + 1]; ++k) {
      if (filed[k] < 0) continue;
      on_boundary[v] = 1;
      for (Index key = filed[k], i = 1; i < corners - 1; ++i, key /= node_count) on_boundary[key % node_count] = 1;
    }
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
  const Vec2 a = (x.row(cells(c, 1)) - x.row(cells(c, 0))).transpose(),
             b = (x.row(cells(c, 2)) - x.row(cells(c, 0))).transpose();
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
  // In parallel: a count and a smallest ratio (NaN never kept) do not depend on the order.
  using Tally = std::pair<Index, double>;
  const Tally tally = tbb::parallel_reduce(
      tbb::blocked_range<Index>(0, out.cells.rows(), 4096), Tally(0, std::numeric_limits<double>::infinity()),
      [&](const tbb::blocked_range<Index>& range, Tally sum) {
        for (Index c = range.begin(); c < range.end(); ++c) {
          const double before = signed_measure(out.points, out.cells, c);
          const double ratio = before != 0 ? signed_measure(moved, out.cells, c) / before : 0.0;
          if (!(ratio > 0)) ++sum.first;
          sum.second = std::min(sum.second, ratio);
        }
        return sum;
      },
      [](const Tally& a, const Tally& b) { return Tally(a.first + b.first, std::min(a.second, b.second)); });
  out.inverted = tally.first;
  out.min_jacobian = tally.second;
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

// Gradients of the barycentric coordinates of a cell (rows) and its signed area (volume).
template <int D, class Points, class Cells>
double simplex_gradients(const Points& x, const Cells& cells, Index c, Eigen::Matrix<double, D + 1, D>& g) {
  Eigen::Matrix<double, D, D> edges;
  for (int i = 0; i < D; ++i) edges.col(i) = (x.row(cells(c, i + 1)) - x.row(cells(c, 0))).transpose();
  const Eigen::Matrix<double, D, D> inverse = edges.inverse();
  g.template bottomRows<D>() = inverse;
  g.row(0) = -inverse.colwise().sum();
  return edges.determinant() / (D == 2 ? 2.0 : 6.0);
}

// One solve on the mesh at positions x: `values` holds the displacement at the fixed nodes; the
// others get the method's solution. P1 elements; in 3D conjugate gradients first (less memory).
template <int D, class Points, class Cells>
Eigen::MatrixXd extension_step(const Points& x, const Cells& cells, const std::vector<char>& fixed,
                               Eigen::MatrixXd values, const ExtendOptions& options) {
  constexpr int corners = D + 1;
  const bool iterative = D == 3;
  // An affine boundary map must come back to rounding, not to the diffusion solver's 1e-10.
  constexpr double tolerance = 1e-12;
  if (options.method == ExtensionMethod::harmonic) {
    // One scalar Laplacian; each component a column of the right-hand side.
    return detail::solve_dirichlet_values(
        x.rows(), cells, fixed, std::move(values),
        [&](Index c) {
          Eigen::Matrix<double, corners, D> g;
          const double measure = std::abs(simplex_gradients<D>(x, cells, c, g));
          return Eigen::Matrix<double, corners, corners>(measure * g * g.transpose());
        },
        iterative, tolerance, Eigen::MatrixXd(x));
  }
  // Linear elasticity with Young's modulus 1 (it cancels with Dirichlet data only): the unknowns
  // are the components, node * D + component, coupled through the strain.
  const double nu = options.poisson_ratio;
  const double mu = 0.5 / (1.0 + nu), lambda = nu / ((1.0 + nu) * (1.0 - 2.0 * nu));
  Eigen::Matrix<Index, Eigen::Dynamic, corners * D, Eigen::RowMajor> dofs(cells.rows(), corners * D);
  for (Index c = 0; c < cells.rows(); ++c) {
    for (int i = 0; i < corners; ++i) {
      for (int a = 0; a < D; ++a) dofs(c, i * D + a) = cells(c, i) * D + a;
    }
  }
  std::vector<char> dof_fixed(x.rows() * D);
  Eigen::MatrixXd flat(x.rows() * D, 1), positions(x.rows() * D, D);
  for (Index v = 0; v < x.rows(); ++v) {
    for (int a = 0; a < D; ++a) {
      dof_fixed[v * D + a] = fixed[v];
      flat(v * D + a, 0) = values(v, a);
      positions.row(v * D + a) = x.row(v);
    }
  }
  flat = detail::solve_dirichlet_values(
      x.rows() * D, dofs, dof_fixed, std::move(flat),
      [&](Index c) {
        Eigen::Matrix<double, corners, D> g;
        const double measure = std::abs(simplex_gradients<D>(x, cells, c, g));
        // The bilinear form 2 mu eps(u):eps(v) + lambda div u div v for u = phi_j e_b, v = phi_i e_a.
        Eigen::Matrix<double, corners * D, corners * D> k;
        for (int i = 0; i < corners; ++i) {
          for (int j = 0; j < corners; ++j) {
            const double dot = g.row(i).dot(g.row(j));
            for (int a = 0; a < D; ++a) {
              for (int b = 0; b < D; ++b) {
                k(i * D + a, j * D + b) =
                    measure * (mu * (a == b ? dot : 0.0) + mu * g(i, b) * g(j, a) + lambda * g(i, a) * g(j, b));
              }
            }
          }
        }
        return k;
      },
      iterative, tolerance, positions);
  for (Index v = 0; v < x.rows(); ++v) {
    for (int a = 0; a < D; ++a) values(v, a) = flat(v * D + a, 0);
  }
  return values;
}

// The motion of the interior: out.displacement holds the boundary displacement at the fixed
// nodes on entry, the displacement of every node on return. In substeps, each moving the
// boundary by an equal share of what remains and solving on the mesh as moved so far; then, if
// asked, the free corners of the cells still inverted moved to untangle them.
template <int D, class Interior>
void solve_motion(Interior& out, const std::vector<char>& fixed, const ExtendOptions& options) {
  // A flat cell has no gradients: its stiffness would be infinite.
  const Index cell_count = out.cells.rows();
  const Index flat = tbb::parallel_reduce(
      tbb::blocked_range<Index>(0, cell_count, 4096), cell_count,
      [&](const tbb::blocked_range<Index>& range, Index first_flat) {
        for (Index c = range.begin(); c < range.end() && c < first_flat; ++c) {
          if (!(std::abs(signed_measure(out.points, out.cells, c)) > 0)) first_flat = c;
        }
        return first_flat;
      },
      [](Index a, Index b) { return std::min(a, b); });
  if (flat < cell_count) {
    detail::invalid("mesh", "cell " + std::to_string(flat) + " is flat (zero " + (D == 2 ? "area" : "volume") + ")");
  }
  const Eigen::MatrixXd boundary = out.displacement;
  Eigen::MatrixXd total = Eigen::MatrixXd::Zero(out.points.rows(), D);
  auto moved = out.points;
  for (int step = 0; step < options.substeps; ++step) {
    const Eigen::MatrixXd share = (boundary - total) / static_cast<double>(options.substeps - step);
    const Eigen::MatrixXd increment = extension_step<D>(moved, out.cells, fixed, share, options);
    if (!increment.allFinite()) {
      throw GeometryError(std::string("the ") + (options.method == ExtensionMethod::harmonic ? "harmonic" : "elastic") +
                          " extension has no finite solution on this mesh" +
                          (step > 0 ? " (substep " + std::to_string(step + 1) + " flattened a cell)" : ""));
    }
    total += increment;
    moved += increment;
  }
  if (options.untangle) {
    constexpr int kSweeps = 30;  // each sweep over the corners of the cells still inverted
    const auto solved = moved;
    detail::untangle(out.points, moved, out.cells, fixed, kSweeps);
    // Only the nodes it moved (moved - points would round every other node's displacement).
    for (Index v = 0; v < moved.rows(); ++v) {
      if (moved.row(v) != solved.row(v)) total.row(v) = moved.row(v) - out.points.row(v);
    }
  }
  out.displacement = total;
  measure_inversions(out);
}

void require_options(const ExtendOptions& options) {
  if (!(options.poisson_ratio >= 0.0 && options.poisson_ratio < 0.5)) {
    detail::invalid("poisson_ratio", "must be at least 0 and below 0.5, got " + std::to_string(options.poisson_ratio));
  }
  if (options.substeps < 1) detail::invalid("substeps", "must be at least 1, got " + std::to_string(options.substeps));
  detail::require_mesh_size(options.mesh_size);
}

// A triangle with its three corners on C1 moves with the boundary field alone: where the field
// brings the three into line or past it (the corners where a limb outline meets its flank
// segment) the triangle flattens or turns over, and neither substeps nor untangling can help.
// Splitting its longest inner edge at the midpoint (both triangles on that edge become two) gives
// every part a free corner, the 2D form of volume_mesh's split_chords. Passes until none is left,
// since a triangle beside one just split waits for the next (bench/README.md "Interior motion
// through a series": limb outlines 10 h apart). Only the vertices and triangles are kept up to date.
void split_boundary_triangles(detail::RegionMesh& mesh) {
  std::vector<char> on_boundary(mesh.on_boundary.begin(), mesh.on_boundary.end());
  for (bool again = true; again;) {
    again = false;
    const Index count = mesh.triangles.rows();
    std::map<std::pair<Index, Index>, std::vector<Index>> sides;  // an edge's triangles
    for (Index t = 0; t < count; ++t) {
      for (int i = 0; i < 3; ++i) {
        const Index a = mesh.triangles(t, i), b = mesh.triangles(t, (i + 1) % 3);
        sides[{std::min(a, b), std::max(a, b)}].push_back(t);
      }
    }
    std::vector<char> taken(count, 0);
    std::vector<Eigen::Matrix<Index, 1, 3>> added;
    std::vector<Eigen::RowVector2d> midpoints;
    for (Index t = 0; t < count; ++t) {
      if (taken[t] || !on_boundary[mesh.triangles(t, 0)] || !on_boundary[mesh.triangles(t, 1)] ||
          !on_boundary[mesh.triangles(t, 2)]) {
        continue;
      }
      std::pair<Index, Index> longest(-1, -1);
      double length = -1.0;
      for (int i = 0; i < 3; ++i) {
        const Index a = mesh.triangles(t, i), b = mesh.triangles(t, (i + 1) % 3);
        const auto& around = sides[{std::min(a, b), std::max(a, b)}];
        const double l = (mesh.vertices.row(a) - mesh.vertices.row(b)).norm();
        if (around.size() == 2 && !taken[around[0]] && !taken[around[1]] && l > length) {
          length = l;
          longest = {a, b};
        }
      }
      if (longest.first < 0) continue;
      const Index m = mesh.vertices.rows() + static_cast<Index>(midpoints.size());
      midpoints.push_back(0.5 * (mesh.vertices.row(longest.first) + mesh.vertices.row(longest.second)));
      // Each triangle on the edge becomes two, the midpoint in place of one end and then the
      // other: the orientation stays.
      for (const Index s : sides[{std::min(longest.first, longest.second), std::max(longest.first, longest.second)}]) {
        taken[s] = 1;
        Eigen::Matrix<Index, 1, 3> second = mesh.triangles.row(s);
        for (int i = 0; i < 3; ++i) {
          if (mesh.triangles(s, i) == longest.first) mesh.triangles(s, i) = m;
          if (second(i) == longest.second) second(i) = m;
        }
        added.push_back(second);
      }
    }
    if (midpoints.empty()) break;
    again = true;
    const Index vertices = mesh.vertices.rows();
    mesh.vertices.conservativeResize(vertices + static_cast<Index>(midpoints.size()), Eigen::NoChange);
    for (std::size_t k = 0; k < midpoints.size(); ++k) {
      mesh.vertices.row(vertices + static_cast<Index>(k)) = midpoints[k];
    }
    on_boundary.resize(static_cast<std::size_t>(mesh.vertices.rows()), 0);
    mesh.triangles.conservativeResize(count + static_cast<Index>(added.size()), Eigen::NoChange);
    for (std::size_t k = 0; k < added.size(); ++k) mesh.triangles.row(count + static_cast<Index>(k)) = added[k];
  }
}

// The mesh size for Mesh_3: the one asked for, else the start triangles' mean edge (checking that
// every corner has a start point, as the surface to mesh).
double default_size(const DisplacementField3& field, const ExtendOptions& options) {
  if (field.faces.rows() == 0) detail::invalid("field", "has no triangles to mesh the region they enclose");
  double total = 0.0;
  for (Index f = 0; f < field.faces.rows(); ++f) {
    for (int i = 0; i < 3; ++i) {
      const Index a = field.faces(f, i);
      if (a < 0 || a >= field.starts.rows() || !field.starts.row(a).allFinite()) {
        detail::invalid("field", "triangle " + std::to_string(f) + " has a corner without a start point: pass mesh=");
      }
    }
    for (int i = 0; i < 3; ++i) {
      total += (field.starts.row(field.faces(f, i)) - field.starts.row(field.faces(f, (i + 1) % 3))).norm();
    }
  }
  if (options.mesh_size > 0.0) return options.mesh_size;
  const double mean = total / (3.0 * field.faces.rows());
  if (!(mean > 0.0) || !std::isfinite(mean)) {
    detail::invalid("field",
                    "its triangles have no finite, non-zero mean edge length to size the mesh by: pass mesh_size");
  }
  return mean;
}

// The field on the given mesh (checked), or with no cells given on the one `make_mesh` puts into
// the result: boundary values from `values_at`, then the solve (the same in 2D and 3D).
template <int D, class Out, class PointsRef, class CellsRef, class MakeMesh, class ValuesAt>
Out extend_on(const PointsRef& mesh_points, const CellsRef& mesh_cells, MakeMesh make_mesh, ValuesAt values_at,
              const ExtendOptions& options) {
  Out out;
  if (mesh_cells.rows() == 0) {
    make_mesh(out);
  } else {
    require_mesh(mesh_points, mesh_cells);
    out.points = mesh_points;
    out.cells = mesh_cells;
  }
  const std::vector<char> fixed = boundary_nodes(out.cells, out.points.rows());
  take_boundary_values(out, fixed, values_at);
  solve_motion<D>(out, fixed, options);
  return out;
}

}  // namespace

InteriorField2 extend_field(const DisplacementField2& field, const Points2Ref& source, const Points2Ref& mesh_points,
                            const FacesRef& mesh_cells, const ExtendOptions& options) {
  require_options(options);
  detail::require_simple_curve(source, true, "source");
  return extend_on<2, InteriorField2>(
      mesh_points, mesh_cells,
      [&](InteriorField2& out) {
        // (require_simple_curve has checked the curve: only its repeats are dropped here.)
        detail::RegionMesh mesh =
            detail::mesh_region({detail::drop_repeats(source, true, "source")}, options.mesh_size);
        split_boundary_triangles(mesh);
        out.points = std::move(mesh.vertices);
        out.cells = std::move(mesh.triangles);
      },
      [&](const Points2& at) { return displacement_at(field, source, true, at); }, options);
}

InteriorField3 extend_field(const DisplacementField3& field, const Points3Ref& mesh_points,
                            const TetrahedraRef& mesh_cells, const ExtendOptions& options) {
  require_options(options);
  return extend_on<3, InteriorField3>(
      mesh_points, mesh_cells,
      [&](InteriorField3& out) {
        detail::VolumeMesh mesh =
            detail::mesh_volume(field.starts, field.faces, default_size(field, options), options.seed, "field");
        out.points = std::move(mesh.vertices);
        out.cells = std::move(mesh.tetrahedra);
      },
      [&](const Points3& at) { return displacement_at(field, at); }, options);
}

}  // namespace morphomap
