// The paper's 3D mapping: minimal distance, normal and diffusion mapping of the vertices of one
// closed surface onto another, with reverse and "auto" (normal, else diffusion where it fails).
#include <morphomap/laplace3d.hpp>
#include <morphomap/surface_mapping.hpp>
#include <morphomap/surface_queries.hpp>

#include "common/run_both.hpp"
#include "common/validation.hpp"
#include "diffusion/shell_diffusion.hpp"
#include "diffusion/shell_mesh.hpp"
#include "mapping/local_diffusion.hpp"
#include "quality/folds.hpp"

#include <morphomap/errors.hpp>

#include <algorithm>
#include <limits>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace morphomap {

namespace {

// A surface checked at the entry (closed, outward), with what the entry knows of it.
struct Surface {
  Points3Ref vertices;
  FacesRef faces;
  double volume;                                  // positive
  const SurfaceIndex* index = nullptr;            // its query index where the caller has one (PreparedSurface)
  const detail::ClosedSurface* closed = nullptr;  // its CGAL form (set by `checked`)
};

// The two surfaces of one call and their nesting (classify_nesting(source, target)), each way
// round: diffusion reuses the entry's conversion and nesting test.
struct Pair {
  Surface source, target;
  detail::Nesting nesting;
  Pair swapped() const { return Pair{target, source, detail::swapped(nesting)}; }
};

// `surface`'s own index, else one built into `built`.
const SurfaceIndex& index_of(const Surface& surface, std::unique_ptr<SurfaceIndex>& built) {
  if (surface.index != nullptr) return *surface.index;
  built = std::make_unique<SurfaceIndex>(surface.vertices, surface.faces);
  return *built;
}

// The pair as diffusion takes it.
detail::ShellPair shell_pair(const Pair& pair, const SurfaceIndex& target_index) {
  const Surface& source = pair.source;
  const Surface& target = pair.target;
  return detail::ShellPair{source.vertices, source.faces,  target.vertices, target.faces, *source.closed,
                           *target.closed,  source.volume, target.volume,   pair.nesting, target_index};
}

// Vectors from the vertices of `pair.source` to `pair.target` (queried through `target_index`,
// built from it) with one basic algorithm; diffusion with `diffusion`'s options. Diffusion's fold
// repair also queries the source: through `source_index` where the caller has one, else through
// one built here.
DisplacementField3 basic(MapMethod method, const Pair& pair, const SurfaceIndex& target_index,
                         const ShellDiffusionOptions& diffusion, const SurfaceIndex* source_index = nullptr) {
  const Surface& source = pair.source;
  const Surface& target = pair.target;
  DisplacementField3 field;
  field.starts = source.vertices;
  field.faces = source.faces;
  switch (method) {
    case MapMethod::minimal_distance:
      field.ends = target_index.closest_points(field.starts).points;
      field.methods.assign(field.size(), Method::minimal_distance);
      break;
    case MapMethod::normal: {
      const Points3 normals = vertex_normals(source.vertices, source.faces);
      field.ends = target_index.line_intersections(field.starts, normals).points;
      field.methods.assign(field.size(), Method::normal);
      break;
    }
    case MapMethod::diffusion: {
      const ShellDiffusionSolution solution = detail::solve_diffusion_3d(shell_pair(pair, target_index), diffusion);
      if (solution.ends.rows() != field.size())
        throw GeometryError("diffusion: the solver returned the wrong number of ends");
      field.ends = solution.ends;  // on the target itself (solve_diffusion_3d puts them there)
      // The streamlines do not cross; the few slivers their discrete form flips are repaired.
      std::unique_ptr<SurfaceIndex> own_index;
      if (source_index == nullptr) {
        own_index = std::make_unique<SurfaceIndex>(source.vertices, source.faces);
        source_index = own_index.get();
      }
      const Points3 placed = field.ends;
      detail::unfold(field.starts, field.ends, field.faces, source.vertices, source.faces, *source_index,
                     target.vertices, target.faces, target_index);
      // Touching vertices went to their closest point, unless the repair has moved them since.
      field.methods.assign(field.size(), Method::diffusion);
      for (Index i = 0; i < field.size(); ++i) {
        if (solution.touching[static_cast<std::size_t>(i)] && field.ends.row(i) == placed.row(i)) {
          field.methods[i] = Method::minimal_distance;
        }
      }
      break;
    }
    default:  // automatic is directed's; the others are refused at the entry (require_surface_method)
      detail::invalid("method", std::string(map_method_name(method)) + " is not a basic 3D method");
  }
  return field;
}

// A field from one surface to another turned round (starts and ends swapped, rows and faces kept,
// methods named the other way round); a row that found nothing keeps its known point, the other
// end NaN.
DisplacementField3 flipped(DisplacementField3 field) {
  std::swap(field.starts, field.ends);
  for (Method& m : field.methods) m = reversed(m);
  return field;
}

bool complete(const DisplacementField3& field) {
  for (Index i = 0; i < field.size(); ++i) {
    if (!field.valid(i)) return false;
  }
  return true;
}

// "auto": normal mapping where it misses nothing and folds no triangle; else, between nested
// surfaces, the normal field with diffusion near where it failed (local_diffusion.hpp); else
// reverse diffusion over the whole surface (the paper's choice), else diffusion (both fold-free
// by construction), else the normal mapping if it missed nothing, else minimal distance (which
// always finds a point): it answers wherever a basic algorithm does.
DisplacementField3 automatic(const Pair& pair, const SurfaceIndex& target_index,
                             const ShellDiffusionOptions& diffusion) {
  const Surface& source = pair.source;
  const Surface& target = pair.target;
  if (diffusion.on_stage) diffusion.on_stage("normal");
  DisplacementField3 normal = basic(MapMethod::normal, pair, target_index, diffusion);
  std::unique_ptr<SurfaceIndex> built;
  const SurfaceIndex& source_index = index_of(source, built);
  const bool missed = !complete(normal);
  const std::vector<char> folded = detail::FoldTest(normal.starts, normal.faces, source.vertices, source.faces,
                                                    source_index, target.vertices, target.faces, target_index)
                                       .folded(normal.ends);
  if (!missed && std::find(folded.begin(), folded.end(), 1) == folded.end()) return normal;
  // Diffusion needs a region between the surfaces; where one of them encloses no volume the
  // attempts would be refused (require_volume), so they are not made.
  const bool diffusable = detail::encloses_volume(source.volume, source.vertices) &&
                          detail::encloses_volume(target.volume, target.vertices);
  if (diffusable && pair.nesting != detail::Nesting::crossing) {
    try {
      std::optional<DisplacementField3> field =
          detail::normal_with_local_diffusion(normal, folded, shell_pair(pair, target_index), source_index, diffusion);
      if (field) return std::move(*field);
    } catch (const GeometryError&) {
    } catch (const InvalidInput&) {  // surfaces whose region diffusion cannot mesh (they coincide in part, say)
    }
  }
  for (const bool backwards : {true, false}) {
    if (!diffusable) break;
    try {
      DisplacementField3 field =
          backwards ? flipped(basic(MapMethod::diffusion, pair.swapped(), source_index, diffusion, &target_index))
                    : basic(MapMethod::diffusion, pair, target_index, diffusion, &source_index);
      if (complete(field)) return field;
    } catch (const GeometryError&) {
    } catch (const InvalidInput&) {  // surfaces whose region diffusion cannot mesh (they coincide in part, say)
    }
  }
  if (!missed) return normal;
  return basic(MapMethod::minimal_distance, pair, target_index, diffusion);
}

DisplacementField3 directed(MapMethod method, const Pair& pair, const ShellDiffusionOptions& diffusion) {
  std::unique_ptr<SurfaceIndex> built;
  const SurfaceIndex& target_index = index_of(pair.target, built);
  if (method == MapMethod::automatic) return automatic(pair, target_index, diffusion);
  return basic(method, pair, target_index, diffusion, pair.source.index);
}

// `surface`'s CGAL form: its own (PreparedSurface), else one converted into `built`.
const detail::ClosedSurface& closed_of(const Surface& surface, std::unique_ptr<const detail::ClosedSurface>& built) {
  if (surface.closed != nullptr) return *surface.closed;
  built = std::make_unique<const detail::ClosedSurface>(surface.vertices, surface.faces);
  return *built;
}

// map_surfaces on two checked surfaces: each converted to CGAL's form and tested for
// self-intersections once, here, for every algorithm and direction the call runs.
DisplacementField3 checked(Surface s1, Surface s2, const SurfaceMappingOptions& options) {
  if (!method_row(options.method).surfaces) {
    detail::invalid("method", std::string(map_method_name(options.method)) + " mapping has no 3D form; use " +
                                  quoted_method_names(&MethodRow::surfaces));
  }
  if (options.method == MapMethod::diffusion) {
    detail::require_volume(s1.volume, s1.vertices, "s1");
    detail::require_volume(s2.volume, s2.vertices, "s2");
  }
  std::unique_ptr<const detail::ClosedSurface> built1, built2;
  detail::run_both([&] { s1.closed = &closed_of(s1, built1); }, [&] { s2.closed = &closed_of(s2, built2); });
  // Both surfaces free of self-intersections (classify_nesting checks), and overlapping: frames
  // of one organ do (see map_curves).
  const detail::Nesting nesting = detail::classify_nesting(*s1.closed, *s2.closed);
  if (nesting == detail::Nesting::disjoint) {
    detail::invalid("s2",
                    "lies apart from s1 (the surfaces neither cross nor enclose one another): consecutive "
                    "frames of one organ overlap; check their units and offsets");
  }
  detail::require_mesh_size(options.diffusion_mesh_size);
  ShellDiffusionOptions diffusion;
  diffusion.mesh_size = options.diffusion_mesh_size;
  diffusion.repeatable = options.diffusion_repeatable;
  diffusion.on_stage = options.on_stage;
  const Pair pair{s1, s2, nesting};
  if (!options.reverse) return directed(options.method, pair, diffusion);
  return flipped(directed(options.method, pair.swapped(), diffusion));
}

}  // namespace

DisplacementField3 map_surfaces(const Points3Ref& v1, const FacesRef& f1, const Points3Ref& v2, const FacesRef& f2,
                                const SurfaceMappingOptions& options) {
  double volume1 = 0.0, volume2 = 0.0;
  detail::run_both(
      [&] {
        volume1 = check_closed_surface(v1, f1, "s1");
        detail::require_outward(volume1, "s1");
      },
      [&] {
        volume2 = check_closed_surface(v2, f2, "s2");
        detail::require_outward(volume2, "s2");
      });
  return checked(Surface{v1, f1, volume1}, Surface{v2, f2, volume2}, options);
}

DisplacementField3 map_surfaces(const PreparedSurface& s1, const PreparedSurface& s2,
                                const SurfaceMappingOptions& options) {
  return checked(Surface{s1.vertices(), s1.faces(), s1.volume(), &s1.index(), &s1.closed()},
                 Surface{s2.vertices(), s2.faces(), s2.volume(), &s2.index(), &s2.closed()}, options);
}

}  // namespace morphomap
