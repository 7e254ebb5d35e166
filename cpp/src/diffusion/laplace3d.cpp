// Diffusion mapping in 3D: P1 finite elements for the Laplace equation on the tetrahedral mesh of
// the region between two closed surfaces (a shell, or the pieces of the symmetric difference of
// crossing surfaces), and streamlines of the recovered gradient. Here the checks and the solve;
// the mesh in shell_sizing.hpp, the streamlines in shell_tracer.hpp.
#include <morphomap/errors.hpp>
#include <morphomap/laplace3d.hpp>
#include <morphomap/surface_queries.hpp>

#include "common/finite_rows.hpp"
#include "common/numbers.hpp"
#include "common/run_both.hpp"
#include "common/validation.hpp"
#include "diffusion/dirichlet.hpp"
#include "diffusion/shell_diffusion.hpp"
#include "diffusion/shell_mesh.hpp"
#include "diffusion/shell_sizing.hpp"
#include "diffusion/shell_tracer.hpp"

#include <Eigen/Dense>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <Eigen/SparseCore>

#include <chrono>
#include <cmath>
#include <memory>
#include <vector>

namespace morphomap {

using detail::kNaN;

namespace {

using Vec3 = Eigen::Vector3d;
using detail::crossing_vertex;
using detail::free_vertex;
using detail::source_vertex;
using detail::target_vertex;

// The P1 solution on the tetrahedra: local stiffness volume * grad phi_i . grad phi_j.
Vector solve_potential(const detail::ShellMesh& mesh, const std::vector<char>& kind) {
  return detail::solve_dirichlet(
      mesh.vertices.rows(), mesh.tetrahedra, kind,
      [&](Index t) {
        Eigen::Matrix<double, 4, 3> g;
        const double volume = std::abs(detail::tetrahedron_gradients(mesh.vertices, mesh.tetrahedra, t, g));
        return Eigen::Matrix4d(volume * g * g.transpose());
      },
      true);
}

double seconds_since(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

}  // namespace

ShellDiffusionSolution solve_diffusion_3d(const Points3Ref& source_vertices, const FacesRef& source_faces,
                                          const Points3Ref& target_vertices, const FacesRef& target_faces,
                                          const ShellDiffusionOptions& options) {
  detail::require_mesh_size(options.mesh_size);
  const auto clock = std::chrono::steady_clock::now();
  // Each surface checked, oriented outwards (Mesh_3 and the nesting tests want that) and put in
  // CGAL's form once, for the nesting, contact, crossing and meshing steps: the two at once.
  struct Checked {
    double volume = 0.0;
    Faces outward;
    std::unique_ptr<const detail::ClosedSurface> closed;
  };
  const auto check = [](const Points3Ref& vertices, const FacesRef& faces, const char* name) {
    Checked checked;
    checked.volume = check_closed_surface(vertices, faces, name);
    detail::require_volume(std::abs(checked.volume), vertices, name);
    checked.outward = faces;
    if (checked.volume < 0.0) checked.outward.col(1).swap(checked.outward.col(2));
    checked.closed = std::make_unique<const detail::ClosedSurface>(vertices, checked.outward);
    return checked;
  };
  Checked source, target;
  detail::run_both([&] { source = check(source_vertices, source_faces, "s1"); },
                   [&] { target = check(target_vertices, target_faces, "s2"); });
  const detail::Nesting nesting = detail::classify_nesting(*source.closed, *target.closed);
  if (nesting == detail::Nesting::disjoint) {
    throw InvalidInput("s2: diffusion mapping needs surfaces that overlap (these lie apart)");
  }
  const SurfaceIndex target_index(target_vertices, target.outward);
  const double nesting_seconds = seconds_since(clock);
  ShellDiffusionSolution solution = detail::solve_diffusion_3d(
      detail::ShellPair{source_vertices, source.outward, target_vertices, target.outward, *source.closed,
                        *target.closed, std::abs(source.volume), std::abs(target.volume), nesting, target_index},
      options);
  solution.seconds.mesh += nesting_seconds;  // the nesting test is part of the meshing stage
  return solution;
}

ShellDiffusionSolution detail::solve_diffusion_3d(const ShellPair& pair, const ShellDiffusionOptions& options,
                                                  const LocalDiffusion* local) {
  const Points3Ref& source_vertices = pair.source_vertices;
  const SurfaceIndex& target_index = pair.target_index;
  const auto stage = [&](const char* name) {
    if (options.on_stage) options.on_stage(name);
  };
  stage("mesh");
  auto clock = std::chrono::steady_clock::now();
  const detail::ShellRegion region = detail::mesh_shell_region(pair, options, local);
  const detail::ShellMesh& mesh = region.mesh;
  const detail::ClearedSource& cleared = region.cleared;

  ShellDiffusionSolution solution;
  solution.seconds.mesh = seconds_since(clock);
  stage("solve");
  clock = std::chrono::steady_clock::now();

  const Index nv = mesh.vertices.rows(), nt = mesh.tetrahedra.rows();
  std::vector<char> kind(nv, free_vertex);
  std::vector<Index> source_facets;  // tetrahedron * 4 + face
  for (Index t = 0; t < nt; ++t) {
    for (int i = 0; i < 4; ++i) {
      const signed char patch = mesh.patches(t, i);
      if (patch != detail::source_face && patch != detail::target_face) continue;
      if (patch == detail::source_face) source_facets.push_back(4 * t + i);
      for (int j = 1; j < 4; ++j) {
        char& k = kind[mesh.tetrahedra(t, (i + j) % 4)];
        const char here = patch == detail::source_face ? source_vertex : target_vertex;
        k = k == free_vertex || k == here ? here : static_cast<char>(crossing_vertex);
      }
    }
  }
  if (source_facets.empty()) throw GeometryError("the mesh of the region has no face on s1");
  solution.potential = solve_potential(mesh, kind);
  solution.seconds.solve = seconds_since(clock);
  stage("trace");
  clock = std::chrono::steady_clock::now();
  detail::ShellExits traced = detail::trace_exits(mesh, solution.potential, kind, source_facets, source_vertices,
                                                  cleared.vertices, local, options.keep_streamlines);
  const Points3& exits = traced.exits;
  std::vector<std::vector<Vec3>>& paths = traced.paths;
  const Index ns = source_vertices.rows();

  // The exit points lie on the mesh's approximation of the target: move them onto the surface.
  const std::vector<Index> reached = detail::finite_rows(exits);
  solution.ends = Points3::Constant(ns, 3, kNaN);
  if (!reached.empty()) {
    const SurfaceHits ends = target_index.closest_points(exits(reached, Eigen::all));
    for (std::size_t k = 0; k < reached.size(); ++k)
      solution.ends.row(reached[k]) = ends.points.row(static_cast<Index>(k));
  }
  // Where the surfaces touch, the vertices map to their closest point (as 2D's contact stretches).
  solution.touching.assign(cleared.touching.begin(), cleared.touching.end());
  for (Index i = 0; i < ns; ++i) {
    if (cleared.touching[i]) solution.ends.row(i) = cleared.closest.row(i);
  }
  if (options.keep_streamlines) {
    solution.streamlines.resize(ns);
    for (Index i = 0; i < ns; ++i) {
      std::vector<Vec3>& path = paths[i];
      path.push_back(solution.ends.row(i).transpose());
      Points3 line(static_cast<Index>(path.size()), 3);
      for (std::size_t k = 0; k < path.size(); ++k) line.row(static_cast<Index>(k)) = path[k].transpose();
      solution.streamlines[i] = std::move(line);
    }
  }
  solution.seconds.trace = seconds_since(clock);
  solution.vertices = mesh.vertices;
  solution.tetrahedra = mesh.tetrahedra;
  return solution;
}

}  // namespace morphomap
