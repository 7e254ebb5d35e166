// The paper's 3D mapping: minimal distance, normal and diffusion mapping of the vertices of one
// closed surface onto another, with reverse and "auto" (normal, else diffusion where it fails).
#include <morphomap/laplace3d.hpp>
#include <morphomap/remesh.hpp>
#include <morphomap/surface_mapping.hpp>
#include <morphomap/surface_queries.hpp>

#include "common/numbers.hpp"
#include "common/run_both.hpp"
#include "common/validation.hpp"
#include "diffusion/shell_diffusion.hpp"
#include "diffusion/shell_mesh.hpp"
#include "mapping/coarse_field.hpp"
#include "mapping/even_surface.hpp"
#include "mapping/local_diffusion.hpp"
#include "mapping/surface_fields.hpp"
#include "mapping/untangled_field.hpp"
#include "quality/folds.hpp"
#include "surfaces/refine.hpp"
#include "surfaces/surface_util.hpp"

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
      // A streamline the tracer loses (it stalls against a sharp crease of the source, such as
      // the rim of a flat cap, bench/README.md "Real 3D stages") takes its neighbours' ends.
      detail::fill_lost_ends(field, target_index);
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

// `field`, mapped from the vertices of pair.target onto pair.source, as the field of the source's
// vertices it defines (surface_fields.hpp), its holes filled and its folds repaired as diffusion's
// are: every method's field is one of S1's vertices, in S1's order.
DisplacementField3 carried(const DisplacementField3& backwards, const Pair& pair, const SurfaceIndex& source_index,
                           const SurfaceIndex& target_index) {
  const Surface& source = pair.source;
  const Surface& target = pair.target;
  DisplacementField3 field = detail::carried_onto_source(flipped(backwards), source.vertices, source.faces);
  detail::fill_lost_ends(field, target_index);
  detail::unfold(field.starts, field.ends, field.faces, source.vertices, source.faces, source_index, target.vertices,
                 target.faces, target_index);
  return field;
}

// What is wrong with a candidate of "auto": vertices without an end and folded triangles.
struct Defects {
  Index unmapped = 0, folded = 0;
  Eigen::RowVector3d where = Eigen::RowVector3d::Zero();  // the mean of the start points concerned
  bool none() const { return unmapped == 0 && folded == 0; }
};

Defects defects(const DisplacementField3& field, const detail::FoldTest& test) {
  Defects d;
  std::vector<char> concerned(static_cast<std::size_t>(field.size()), 0);
  for (Index i = 0; i < field.size(); ++i) {
    if (!field.valid(i)) concerned[static_cast<std::size_t>(i)] = 1, ++d.unmapped;
  }
  const std::vector<char> folded = test.folded(field.ends);
  for (Index k = 0; k < field.faces.rows(); ++k) {
    if (!folded[static_cast<std::size_t>(k)]) continue;
    ++d.folded;
    for (int j = 0; j < 3; ++j) concerned[static_cast<std::size_t>(field.faces(k, j))] = 1;
  }
  Index count = 0;
  for (Index i = 0; i < field.size(); ++i) {
    if (concerned[static_cast<std::size_t>(i)] && field.starts.row(i).allFinite())
      d.where += field.starts.row(i), ++count;
  }
  if (count > 0) d.where /= static_cast<double>(count);
  return d;
}

// The surfaces of one call in one direction: the user's, and the pair diffusion runs on — the
// user's, or copies whose poor triangles are refined with the user's vertices kept as their
// first rows (surfaces/refine.hpp: diffusion traces from long thin triangles badly, bench/README.md
// "Real 3D stages"). With each surface's query index.
struct Work {
  Pair user, refined;
  const SurfaceIndex *user_source, *user_target, *refined_source, *refined_target;
  bool is_refined;
  Work swapped() const {
    return Work{user.swapped(), refined.swapped(), user_target, user_source,
                refined_target, refined_source,    is_refined};
  }
};

// A field of the refined source's vertices as one of the user's: the user's vertices are its
// first rows; their ends put on the user's target (they lie on the refined copy, whose vertices
// lie on it), the folds this leaves repaired as diffusion's are.
DisplacementField3 restricted(const DisplacementField3& refined, const Work& work) {
  const Surface& source = work.user.source;
  const Surface& target = work.user.target;
  const Index n = source.vertices.rows();
  DisplacementField3 field;
  field.starts = source.vertices;
  field.faces = source.faces;
  field.methods.assign(refined.methods.begin(), refined.methods.begin() + n);
  field.ends = refined.ends.topRows(n);
  const SurfaceHits on_target = work.user_target->closest_points(field.ends);
  for (Index i = 0; i < n; ++i) {
    if (field.ends.row(i).allFinite()) field.ends.row(i) = on_target.points.row(i);
  }
  detail::fill_lost_ends(field, *work.user_target);
  detail::unfold(field.starts, field.ends, field.faces, source.vertices, source.faces, *work.user_source,
                 target.vertices, target.faces, *work.user_target);
  return field;
}

// Diffusion from the source's vertices (backwards: from the target's, carried onto the source's)
// on the work pair, as a field of the user's source vertices.
DisplacementField3 diffusion_field(const Work& work, bool backwards, const ShellDiffusionOptions& diffusion) {
  const Pair& pair = work.refined;
  const SurfaceIndex& source_index = *work.refined_source;
  const SurfaceIndex& target_index = *work.refined_target;
  DisplacementField3 field =
      backwards ? carried(basic(MapMethod::diffusion, pair.swapped(), source_index, diffusion, &target_index), pair,
                          source_index, target_index)
                : basic(MapMethod::diffusion, pair, target_index, diffusion, &source_index);
  return work.is_refined ? restricted(field, work) : field;
}

// `field` with the ends around its folded triangles (within 0 to kSmoothingRings edges of them)
// re-placed by fill_lost_ends — the harmonic interpolation of the ends around them, put on S2 —
// the first ring that leaves no fold, or nothing. The folds that diffusion's discrete streamlines
// and unfold leave are a few triangles wide (bench/README.md "Real 3D stages").
constexpr int kSmoothingRings = 4;
std::optional<DisplacementField3> smoothed_over_folds(const DisplacementField3& field, const detail::FoldTest& test,
                                                      const SurfaceIndex& target_index) {
  const std::vector<char> folded = test.folded(field.ends);
  for (int rings = 0; rings <= kSmoothingRings; ++rings) {
    DisplacementField3 trial = field;
    for (const Index i : detail::rows_near(field, folded, rings)) trial.ends.row(i).setConstant(detail::kNaN);
    detail::fill_lost_ends(trial, target_index);
    if (defects(trial, test).none()) return trial;
  }
  return std::nullopt;
}

// "auto": one vector per vertex of S1, every one mapped and no triangle folded, or GeometryError.
// Tried in turn, the first such field returned: normal mapping; between nested surfaces, the
// normal field with diffusion near where it failed (local_diffusion.hpp); where S1 is large and
// `coarsen`, auto on coarse copies of the pair carried back (coarse_field.hpp), then the complete
// one with the fewest folds so far untangled (untangled_field.hpp); reverse diffusion carried onto
// S1's vertices (the paper's choice where normal mapping fails) and diffusion, in that order
// unless S2 has fewer vertices than S1; the complete one with the fewest folds so far, untangled,
// where it is another; minimal distance; reverse normal mapping and reverse minimal distance,
// carried, unless the coarse copies were mapped; then the complete one with the fewest folds,
// untangled, where it is another.
// Diffusion's lost streamlines are filled and its turned slivers repaired within each. `outer`:
// where this runs the other way round (reverse), the call's own work pair: each candidate is
// carried onto its S1 and judged there.
DisplacementField3 checked(Surface s1, Surface s2, const SurfaceMappingOptions& options, bool coarsen);

DisplacementField3 automatic(const Work& work, const ShellDiffusionOptions& diffusion, const Work* outer = nullptr,
                             bool coarsen = true) {
  const Pair& pair = work.user;
  const Surface& source = pair.source;
  const Surface& target = pair.target;
  const SurfaceIndex& source_index = *work.user_source;
  const SurfaceIndex& target_index = *work.user_target;
  // What the call answers with, and the test it must pass: on the call's own S1.
  const Work& call = outer != nullptr ? *outer : work;
  const Surface& s1 = call.user.source;
  const Surface& s2 = call.user.target;
  const detail::FoldTest test(s1.vertices, s1.faces, s1.vertices, s1.faces, *call.user_source, s2.vertices, s2.faces,
                              *call.user_target);
  const auto answer = [&](DisplacementField3 field) {
    return outer == nullptr ? field : carried(field, outer->user, *outer->user_source, *outer->user_target);
  };
  if (diffusion.on_stage) diffusion.on_stage("normal");
  DisplacementField3 normal = basic(MapMethod::normal, pair, target_index, diffusion);
  DisplacementField3 normal_answer = answer(normal);
  const Defects normal_defects = defects(normal_answer, test);
  if (normal_defects.none()) return normal_answer;
  std::vector<std::pair<std::string, Defects>> tried{{"normal", normal_defects}};
  // The complete candidate with the fewest folded triangles, for the last resort, and whether the
  // last resort has failed on it already.
  std::optional<DisplacementField3> least;
  Index least_folded = 0;
  bool least_tried = false;
  const auto keep = [&](const DisplacementField3& field, const Defects& found) {
    if (found.unmapped == 0 && (!least || found.folded < least_folded)) {
      least = field, least_folded = found.folded, least_tried = false;
    }
  };
  const auto last_resort = [&]() -> std::optional<DisplacementField3> {
    if (!least || least_tried) return std::nullopt;
    if (diffusion.on_stage) diffusion.on_stage("untangle");
    if (std::optional<DisplacementField3> field = detail::untangled(
            *least, test, s1.vertices, s1.faces, *call.user_source, s2.vertices, s2.faces, *call.user_target))
      return field;
    least_tried = true;
    tried.emplace_back("the least folded of these, its ends moved along s2: folds remain", Defects{-1, -1});
    return std::nullopt;
  };
  keep(normal_answer, normal_defects);
  // Diffusion needs a region between the surfaces; where one of them encloses no volume the
  // attempts would be refused (require_volume), so they are not made.
  const bool diffusable = detail::encloses_volume(source.volume, source.vertices) &&
                          detail::encloses_volume(target.volume, target.vertices);
  if (diffusable && pair.nesting != detail::Nesting::crossing) {
    try {
      const std::vector<char> folded =
          outer == nullptr ? test.folded(normal.ends)
                           : detail::FoldTest(source.vertices, source.faces, source.vertices, source.faces,
                                              source_index, target.vertices, target.faces, target_index)
                                 .folded(normal.ends);
      std::optional<DisplacementField3> field =
          detail::normal_with_local_diffusion(normal, folded, shell_pair(pair, target_index), source_index, diffusion);
      if (field) {
        DisplacementField3 local = answer(std::move(*field));
        if (defects(local, test).none()) return local;
      }
    } catch (const GeometryError&) {
    } catch (const InvalidInput&) {  // surfaces whose region diffusion cannot mesh (they coincide in part, say)
    }
  }
  // A large S1 (thousands of small triangles, contoured from voxels) through coarse copies of the
  // pair: auto on copies remeshed at about kCoarseVertices vertices of S1, carried back. The
  // voxelised limb stages 270 <-> 290 h map so in 5-7 s, where every whole-resolution candidate
  // folded (bench/README.md "Real 3D stages"). Not reversed: that call's S1 is the other surface.
  const bool coarse_tried = coarsen && outer == nullptr && diffusable && detail::worth_coarsening(s1.vertices);
  if (coarse_tried) {
    if (diffusion.on_stage) diffusion.on_stage("coarse copies");
    const double edge = detail::coarse_edge(s1.vertices, s1.faces);
    const std::string name = "auto on copies remeshed at edge length " + std::to_string(edge);
    std::optional<DisplacementField3> coarse;
    TriangleSurface c1, c2;
    try {
      detail::run_both([&] { c1 = remesh_surface(s1.vertices, s1.faces, edge, detail::kCoarseRemeshing); },
                       [&] { c2 = remesh_surface(s2.vertices, s2.faces, edge, detail::kCoarseRemeshing); });
      SurfaceMappingOptions options;
      options.diffusion_repeatable = diffusion.repeatable;
      options.on_stage = diffusion.on_stage;
      const Surface copy1{c1.vertices, c1.faces, check_closed_surface(c1.vertices, c1.faces, "coarse copy of s1")};
      const Surface copy2{c2.vertices, c2.faces, check_closed_surface(c2.vertices, c2.faces, "coarse copy of s2")};
      try {
        coarse = checked(copy1, copy2, options, false);
      } catch (const GeometryError&) {  // its own message lists the copies' candidates
        tried.emplace_back(name + ": no complete, fold-free field there either", Defects{-1, -1});
      }
    } catch (const GeometryError& error) {  // remeshing that could not repair a self-intersection
      tried.emplace_back(name + " (" + error.what() + ")", Defects{-1, -1});
    } catch (const InvalidInput& error) {  // copies that are not closed, outward and overlapping
      tried.emplace_back(name + " (" + error.what() + ")", Defects{-1, -1});
    }
    if (coarse) {
      DisplacementField3 field =
          detail::carried_from_coarse(*coarse, c2.vertices, c2.faces, s1.vertices, s1.faces, *call.user_source,
                                      s2.vertices, s2.faces, *call.user_target);
      const Defects found = defects(field, test);
      if (found.none()) return field;
      tried.emplace_back(name + ", carried", found);
      keep(field, found);
      // Its few folds (slivers crowded where S2 creases) turned back at once, before the
      // whole-resolution diffusions: the unblurred voxel limb 290 -> 270 h maps so in 6.2 s, not 43.
      if (std::optional<DisplacementField3> repaired = last_resort()) return *repaired;
    }
  }
  // Reverse diffusion first, the paper's choice, where S2 has at least as many vertices as S1. Its
  // field, from S2's vertices, reaches S1's by interpolation, which folds where S2 is the coarser:
  // limb 270 -> 250 h as given (820 vertices onto 226) folded after 8 s spent meshing from the
  // coarse stage, and forward diffusion then mapped it in 1.3 s (bench/README.md "Real 3D stages").
  const bool reverse_first = s2.vertices.rows() >= s1.vertices.rows();
  for (const bool backwards : {reverse_first, !reverse_first}) {
    if (!diffusable) break;
    const char* name = backwards ? "reverse diffusion" : "diffusion";
    try {
      // Reversed, the work's other way round is the call's own direction: mapped there at once,
      // not carried twice.
      DisplacementField3 field = outer != nullptr ? diffusion_field(*outer, !backwards, diffusion)
                                                  : diffusion_field(work, backwards, diffusion);
      const Defects found = defects(field, test);
      if (found.none()) return field;
      if (found.unmapped == 0) {
        if (std::optional<DisplacementField3> smoothed = smoothed_over_folds(field, test, *call.user_target))
          return *smoothed;
      }
      tried.emplace_back(name, found);
      keep(field, found);
    } catch (const GeometryError& error) {
      tried.emplace_back(std::string(name) + " (" + error.what() + ")", Defects{-1, -1});
    } catch (const InvalidInput& error) {
      tried.emplace_back(std::string(name) + " (" + error.what() + ")", Defects{-1, -1});
    }
  }
  // The least folded field so far (diffusion's, as a rule) turned back before the cheap ways, which
  // map less well where they map at all (minimal distance leaves parts of S2 unreached): the
  // blurred voxel limb 290 -> 270 h maps so in 19 s, not 27 (bench/README.md "Real 3D stages").
  if (std::optional<DisplacementField3> field = last_resort()) return *field;
  // The cheap ways last: minimal distance, and normal mapping and minimal distance from S2's
  // vertices carried onto S1's (where S2 is the finer or the smoother surface, say).
  DisplacementField3 nearest = answer(basic(MapMethod::minimal_distance, pair, target_index, diffusion));
  const Defects nearest_defects = defects(nearest, test);
  if (nearest_defects.none()) return nearest;
  tried.emplace_back("minimal distance", nearest_defects);
  keep(nearest, nearest_defects);
  // Not where coarse copies were mapped, whose candidates include these: carried from a large S2
  // they cost the voxelised limb 270 -> 250 h 10-16 s and folded 694-2,475 triangles
  // (bench/README.md "Real 3D stages").
  for (const MapMethod method : {MapMethod::normal, MapMethod::minimal_distance}) {
    if (coarse_tried) break;
    DisplacementField3 back = outer != nullptr ? basic(method, outer->user, *outer->user_target, diffusion)
                                               : carried(basic(method, pair.swapped(), source_index, diffusion), pair,
                                                         source_index, target_index);
    const Defects found = defects(back, test);
    if (found.none()) return back;
    tried.emplace_back(method == MapMethod::normal ? "reverse normal" : "reverse minimal distance", found);
    keep(back, found);
  }
  if (std::optional<DisplacementField3> field = last_resort()) return *field;
  std::string message = "map_surfaces: no complete, fold-free field from the " + std::to_string(s1.vertices.rows()) +
                        " vertices of s1 to s2 (";
  for (std::size_t k = 0; k < tried.size(); ++k) {
    const auto& [name, found] = tried[k];
    message += (k > 0 ? "; " : "") + name;
    if (found.unmapped < 0) continue;
    message += ": " + std::to_string(found.unmapped) + " vertices unmapped, " + std::to_string(found.folded) +
               " triangles folded around (" + std::to_string(found.where.x()) + ", " + std::to_string(found.where.y()) +
               ", " + std::to_string(found.where.z()) + ")";
  }
  throw GeometryError(message +
                      "); remesh the surfaces finer and more evenly (remesh_surface), or choose a method and "
                      "inspect quality(field).folds");
}

DisplacementField3 directed(MapMethod method, const Work& work, const ShellDiffusionOptions& diffusion,
                            bool coarsen = true) {
  if (method == MapMethod::automatic) return automatic(work, diffusion, nullptr, coarsen);
  if (method == MapMethod::diffusion) return diffusion_field(work, false, diffusion);
  return basic(method, work.user, *work.user_target, diffusion, work.user_source);
}

// "optimal": auto's field (complete and fold-free, or auto's error), its ends then moved along S2
// until every triangle's image keeps its share of S2's area (even_ends), every vector labelled
// optimal.
DisplacementField3 evened(DisplacementField3 field, const Pair& user, const ShellDiffusionOptions& diffusion) {
  const Surface& s1 = user.source;
  const Surface& s2 = user.target;
  if (diffusion.on_stage) diffusion.on_stage("optimal");
  const detail::FoldTest test(s1.vertices, s1.faces, s1.vertices, s1.faces, *s1.index, s2.vertices, s2.faces,
                              *s2.index);
  field.ends = detail::even_ends(field.starts, field.ends, field.faces, test, s2.vertices, s2.faces, *s2.index,
                                 detail::area_factor(s1.vertices, s1.faces, s2.vertices, s2.faces));
  std::fill(field.methods.begin(), field.methods.end(), Method::optimal);
  return field;
}

// `surface`'s CGAL form: its own (PreparedSurface), else one converted into `built`.
const detail::ClosedSurface& closed_of(const Surface& surface, std::unique_ptr<const detail::ClosedSurface>& built) {
  if (surface.closed != nullptr) return *surface.closed;
  built = std::make_unique<const detail::ClosedSurface>(surface.vertices, surface.faces);
  return *built;
}

double median_edge(const Points3Ref& vertices, const FacesRef& faces) {
  std::vector<double> lengths;
  lengths.reserve(static_cast<std::size_t>(3 * faces.rows()));
  for (Index k = 0; k < faces.rows(); ++k) {
    for (int j = 0; j < 3; ++j)
      lengths.push_back((vertices.row(faces(k, j)) - vertices.row(faces(k, (j + 1) % 3))).norm());
  }
  std::nth_element(lengths.begin(), lengths.begin() + static_cast<std::ptrdiff_t>(lengths.size() / 2), lengths.end());
  return lengths[lengths.size() / 2];
}

// A surface with poor triangles refined at its median edge length (or half of it), keeping its vertices (what
// `refined` points at, its CGAL form in `closed`), else the surface itself.
struct Refined {
  TriangleSurface mesh;
  std::unique_ptr<const detail::ClosedSurface> closed;
  std::unique_ptr<SurfaceIndex> index;
};
Surface refined_surface(const Surface& surface, Refined& refined) {
  if (!detail::has_poor_triangles(surface.vertices, surface.faces)) return surface;
  // Held vertices close to a thin triangle's far side can make the remeshed surface touch
  // itself at the median edge length; half of it resolves them.
  const double edge = median_edge(surface.vertices, surface.faces);
  try {
    refined.mesh = detail::refined_keeping_vertices(surface.vertices, surface.faces, edge);
  } catch (const GeometryError&) {
    refined.mesh = detail::refined_keeping_vertices(surface.vertices, surface.faces, 0.5 * edge);
  }
  refined.closed = std::make_unique<const detail::ClosedSurface>(refined.mesh.vertices, refined.mesh.faces);
  refined.index = std::make_unique<SurfaceIndex>(refined.mesh.vertices, refined.mesh.faces);
  const double volume = check_closed_surface(refined.mesh.vertices, refined.mesh.faces, "refined surface");
  return Surface{refined.mesh.vertices, refined.mesh.faces, volume, refined.index.get(), refined.closed.get()};
}

// The work pair of `user` (whose surfaces have their index and CGAL form): refined copies where a
// surface's triangles are poor and both enclose volume, else the user's own.
Work work_pair(const Pair& user, Refined& refined1, Refined& refined2) {
  const Surface& s1 = user.source;
  const Surface& s2 = user.target;
  const Work plain{user, user, s1.index, s2.index, s1.index, s2.index, false};
  if (!detail::encloses_volume(s1.volume, s1.vertices) || !detail::encloses_volume(s2.volume, s2.vertices))
    return plain;
  std::optional<Surface> r1, r2;
  try {
    detail::run_both([&] { r1.emplace(refined_surface(s1, refined1)); },
                     [&] { r2.emplace(refined_surface(s2, refined2)); });
  } catch (const GeometryError&) {  // a refinement that would intersect itself: diffusion on the user's
    return plain;
  }
  if (!refined1.closed && !refined2.closed) return plain;
  const detail::Nesting nesting = detail::classify_nesting(*r1->closed, *r2->closed);
  if (nesting == detail::Nesting::disjoint) return plain;
  return Work{user, Pair{*r1, *r2, nesting}, s1.index, s2.index, r1->index, r2->index, true};
}

// map_surfaces on two checked surfaces: each converted to CGAL's form and tested for
// self-intersections once, here, for every algorithm and direction the call runs.
DisplacementField3 checked(Surface s1, Surface s2, const SurfaceMappingOptions& options, bool coarsen) {
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
  std::unique_ptr<SurfaceIndex> index_built1, index_built2;
  // S1's own index serves auto's fold test, diffusion's repair and carrying a reversed field
  // back; normal mapping and minimal distance query S2 alone.
  const bool starts_from_auto = options.method == MapMethod::automatic || options.method == MapMethod::optimal;
  const bool source_queried = options.reverse || starts_from_auto || options.method == MapMethod::diffusion;
  detail::run_both([&] { s1.index = source_queried ? &index_of(s1, index_built1) : s1.index; },
                   [&] { s2.index = &index_of(s2, index_built2); });
  const Pair user{s1, s2, nesting};
  Refined refined1, refined2;
  const bool diffuses = options.method == MapMethod::diffusion || starts_from_auto;
  const Work work =
      diffuses ? work_pair(user, refined1, refined2) : Work{user, user, s1.index, s2.index, s1.index, s2.index, false};
  if (options.method == MapMethod::optimal) {
    return evened(options.reverse ? automatic(work.swapped(), diffusion, &work) : automatic(work, diffusion), user,
                  diffusion);
  }
  if (!options.reverse) return directed(options.method, work, diffusion, coarsen);
  if (options.method == MapMethod::automatic) return automatic(work.swapped(), diffusion, &work);
  return carried(directed(options.method, work.swapped(), diffusion), user, *s1.index, *s2.index);
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
  return checked(Surface{v1, f1, volume1}, Surface{v2, f2, volume2}, options, true);
}

DisplacementField3 map_surfaces(const PreparedSurface& s1, const PreparedSurface& s2,
                                const SurfaceMappingOptions& options) {
  return checked(Surface{s1.vertices(), s1.faces(), s1.volume(), &s1.index(), &s1.closed()},
                 Surface{s2.vertices(), s2.faces(), s2.volume(), &s2.index(), &s2.closed()}, options, true);
}

}  // namespace morphomap
