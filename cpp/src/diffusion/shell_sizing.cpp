// The mesh that 3D diffusion solves on: contact cleared, element sizes chosen, the region between
// the surfaces meshed by Mesh_3 in a child process, again with other choices after a crash.
#include "diffusion/shell_sizing.hpp"

#include <morphomap/errors.hpp>
#include <morphomap/surface_queries.hpp>

#include "diffusion/mesh_in_child.hpp"
#include "surfaces/surface_util.hpp"

#include <Eigen/Core>

#include <algorithm>
#include <cmath>
#include <memory>
#include <string>
#include <utility>

namespace morphomap {

namespace {

using Vec3 = Eigen::Vector3d;
constexpr double kSourceFraction = 0.02;
// The finest element size near a surface, as a fraction of its bounding diagonal (below).
constexpr double kFinestFraction = 0.015;
constexpr int kMeshAttempts = 3;
// Away from the part a local diffusion traces, the sizes grow by this times the distance beyond
// its focus, up to kCoarsening times (bench/README.md, "A new bud, locally").
constexpr double kFocusGrading = 0.25;
constexpr double kCoarsening = 4.0;
constexpr const char* kMeshing = "meshing the region between the surfaces";
constexpr double kFacetDistanceNested = 0.2;
constexpr double kFacetDistanceCrossing = 0.05;
// Surfaces closer than this fraction of their finer mean edge touch (as 2D's contact tolerance).
constexpr double kTouchFraction = 0.01;
// Where they come closer than this fraction of it, the source is pulled back to it (contact3d.hpp):
// a thinner sliver would need elements of its own thickness.
constexpr double kClearanceFraction = 0.5;
constexpr int kClearanceAttempts = 5;

struct SurfaceFacts {
  double volume = 0.0;  // positive: the faces are oriented outwards
  double area = 0.0;
  double mean_edge = 0.0;
};

// Measures a surface that passed check_closed_surface and require_volume (`volume`: the size of
// its volume).
SurfaceFacts measure_surface(const Points3Ref& vertices, const FacesRef& faces, double volume) {
  SurfaceFacts facts;
  facts.volume = volume;
  facts.area = detail::surface_area(vertices, faces);
  for (Index f = 0; f < faces.rows(); ++f) {
    const Vec3 a = detail::corner(vertices, faces, f, 0), b = detail::corner(vertices, faces, f, 1),
               c = detail::corner(vertices, faces, f, 2);
    facts.mean_edge += ((b - a).norm() + (c - b).norm() + (a - c).norm()) / 3.0;
  }
  facts.mean_edge /= faces.rows();
  return facts;
}

// The source cleared of its contact with the target (contact3d.hpp), and how it then lies
// against the target. Pulling back may make the source meet itself (a sliver of marching cubes
// turned over, a neck narrower than the clearance): then again with half the clearance, down to
// 1/32 of the edge, before the contact is refused (bench/README.md, "Contact patches cut out").
struct Cleared {
  detail::ClearedSource source;
  detail::Nesting nesting;
  std::unique_ptr<const detail::ClosedSurface> surface;  // of the source when it moved (else none)
};

Cleared clear_and_classify(const Points3Ref& source_vertices, const FacesRef& source_faces,
                           const Points3Ref& target_vertices, const FacesRef& target_faces,
                           const detail::ClosedSurface& target_surface, const SurfaceIndex& target_index,
                           double finer_edge, detail::Nesting nesting) {
  double fraction = kClearanceFraction;
  for (int attempt = 0;; ++attempt, fraction *= 0.5) {
    Cleared cleared{detail::clear_contact(source_vertices, source_faces, target_vertices, target_faces, target_surface,
                                          target_index, fraction * finer_edge, kTouchFraction * finer_edge),
                    nesting, nullptr};
    if (cleared.source.moved == 0) return cleared;
    try {
      cleared.surface = std::make_unique<const detail::ClosedSurface>(cleared.source.vertices, source_faces);
      cleared.nesting = detail::classify_nesting(*cleared.surface, target_surface);
      return cleared;
    } catch (const InvalidInput&) {
      if (attempt == kClearanceAttempts - 1) {
        Index touching = 0;
        for (const char t : cleared.source.touching) touching += t;
        throw InvalidInput("s2: comes within " + std::to_string(fraction * finer_edge) + " of s1 over a patch (" +
                           std::to_string(cleared.source.moved) + " vertices, " + std::to_string(touching) +
                           " touching), and pulling s1 back from it there makes s1 intersect itself; diffusion "
                           "cannot map these surfaces: use 'auto' (which falls back) or 'normal'");
      }
    }
  }
}

// The largest element size when the caller gives none: a quarter of the mean gap, four elements
// across the shell. In a thin shell (frames a voxel apart) that is finer than the surfaces'
// own spacing, and the tetrahedra grow as the area over the gap squared (a 2.5k-vertex swell pair
// 0.76 voxel apart: 970k tetrahedra, over a minute); there half the spacing is fine enough, but
// never more than half the gap, two elements across. Measured in bench/README.md, "Thin shells".
double default_cell_size(double gap, double spacing) {
  return std::max(0.25 * gap, std::min(0.5 * gap, 0.5 * spacing));
}

}  // namespace

detail::ShellRegion detail::mesh_shell_region(const ShellPair& pair, const ShellDiffusionOptions& options,
                                              const LocalDiffusion* local) {
  const Points3Ref& source_vertices = pair.source_vertices;
  const Points3Ref& target_vertices = pair.target_vertices;
  const SurfaceFacts source = measure_surface(source_vertices, pair.source_faces, pair.source_volume);
  const SurfaceFacts target = measure_surface(target_vertices, pair.target_faces, pair.target_volume);
  detail::Nesting nesting = pair.nesting;
  const detail::ClosedSurface& given_source = pair.source;
  const detail::ClosedSurface& target_surface = pair.target;
  const SurfaceIndex& target_index = pair.target_index;
  const double finer_edge = std::min(source.mean_edge, target.mean_edge);
  Cleared cleared_pair = clear_and_classify(source_vertices, pair.source_faces, target_vertices, pair.target_faces,
                                            target_surface, target_index, finer_edge, nesting);
  const detail::ClearedSource& cleared = cleared_pair.source;
  nesting = cleared_pair.nesting;
  // Bodies that only touch from outside count as crossing until the contact is cleared.
  if (nesting == detail::Nesting::disjoint) {
    throw InvalidInput(
        "s2: only touches s1 from outside (the surfaces neither cross nor enclose one another); "
        "diffusion mapping needs surfaces that overlap");
  }
  // From here on the source is the cleared one: it bounds the region that is meshed and solved.
  const detail::ClosedSurface& source_surface = cleared_pair.surface ? *cleared_pair.surface : given_source;
  std::unique_ptr<detail::CrossingRegion> crossing;
  if (nesting == detail::Nesting::crossing) {
    crossing = std::make_unique<detail::CrossingRegion>(source_surface, target_surface);
  }

  // Sizes: the input spacing at each surface, growing by a tenth of the distance from it, never
  // above mesh_size (default: a quarter of the mean gap, the region's volume over the mean area of
  // the surfaces). Measured between spheres of radii 1 and 4: the end-point error falls about
  // linearly with the element size in the bulk, and removing slivers (exude) buys more accuracy
  // than it costs time.
  const double volume = crossing ? crossing->volume() : std::abs(target.volume - source.volume);
  // Where the surfaces touch, they bound no region: leave that part out of the mean.
  const double gap = volume / std::max(0.5 * (source.area + target.area) - cleared.near_area, 0.05 * source.area);
  // The input spacing: the mean edge, but not finer than 1.5% of a surface's diagonal: a finer
  // spacing describes the surface, not a shape the field must resolve (where the surface curves,
  // facet_distance refines), and following it made the mesh grow with the surfaces' resolution
  // (five times the tetrahedra, eight times the time, for a lumpy pair of 100k faces). 1.5%
  // rather than 1%: an organ pair's ends then move by about a quarter of a percent of the gap from
  // a much finer mesh's, less than the concentric spheres' row errs by, with fewer than half the
  // tetrahedra (bench/README.md, "The finest element size"). Near the source, where the streamlines start, the
  // elements stay within a fraction of the source's size however coarse its triangles are (the end
  // error follows the element size there: concentric spheres r = 1 -> 4 with 642 vertices gave
  // RMS 0.018 at the triangles' size).
  const double source_diagonal = (source_vertices.colwise().maxCoeff() - source_vertices.colwise().minCoeff()).norm();
  const double target_diagonal = (target_vertices.colwise().maxCoeff() - target_vertices.colwise().minCoeff()).norm();
  const double source_spacing = std::max(source.mean_edge, kFinestFraction * source_diagonal);
  const double target_spacing = std::max(target.mean_edge, kFinestFraction * target_diagonal);
  detail::ShellMeshCriteria criteria;
  criteria.cell_size =
      options.mesh_size > 0.0 ? options.mesh_size : default_cell_size(gap, std::min(source_spacing, target_spacing));
  criteria.source_size = std::min({source_spacing, criteria.cell_size, kSourceFraction * source_diagonal});
  criteria.target_size = std::min(target_spacing, criteria.cell_size);
  criteria.grading = 0.1;
  criteria.exude = true;
  criteria.parallel = !options.repeatable && !crossing;
  if (local != nullptr) {
    if (crossing) throw GeometryError("diffusion for part of s1 needs nested surfaces");
    criteria.focus = local->focus;
    criteria.focus_radius = local->radius;
    criteria.focus_grading = kFocusGrading;
    criteria.coarsening = kCoarsening;
  }
  // Between nested surfaces the boundary facets may stray a fifth of the element size from the
  // surfaces: at 0.05 Mesh_3 chased every crease of an unsmoothed marching-cubes surface (a
  // 2k-vertex swell pair: 917k tetrahedra, 128 s; at 0.2: 265k, 15 s), while the concentric
  // spheres' and the Figure 12 pair's accuracy stays (bench/README.md, "Facet distance between
  // nested surfaces") and the folds its slivers cost are repaired. Where the surfaces cross, the pieces taper to wedges
  // at the crossing curves and their facets must follow the surfaces closely (at 0.2 the round trip of the crossing
  // pair grew from 2.4e-3 to 6.0e-3 RMS, and ends near the curve fell on the wrong side).
  criteria.facet_distance =
      (crossing ? kFacetDistanceCrossing : kFacetDistanceNested) * std::min(criteria.source_size, criteria.target_size);
  // In a child process (see mesh_in_child.hpp); after a crash, again with other random choices
  // and sizes a little finer (the crashes come and go with both).
  detail::ShellMesh mesh;
  const detail::ShellMeshCriteria requested = criteria;
  for (int attempt = 0;; ++attempt) {
    const double finer = 1.0 - 0.15 * attempt;
    criteria.seed = attempt;
    criteria.cell_size = finer * requested.cell_size;
    criteria.source_size = finer * requested.source_size;
    criteria.target_size = finer * requested.target_size;
    criteria.facet_distance = finer * requested.facet_distance;
    try {
      const auto make = [&](bool threads) {
        detail::ShellMeshCriteria used = criteria;
        used.parallel = criteria.parallel && threads;
        return crossing ? crossing->mesh(used)
                        : detail::mesh_shell(source_surface, target_surface, nesting == detail::Nesting::source_inside,
                                             used);
      };
      mesh = criteria.parallel ? detail::mesh_in_child_threaded(make, kMeshing)
                               : detail::mesh_in_child([&] { return make(false); }, kMeshing);
      break;
    } catch (const detail::MesherCrashed& crash) {
      if (attempt + 1 == kMeshAttempts) {
        throw GeometryError(std::string(crash.what()) + " in " + std::to_string(kMeshAttempts) +
                            " attempts; try another mesh_size");
      }
    }
  }
  return ShellRegion{std::move(mesh), std::move(cleared_pair.source)};
}

}  // namespace morphomap
