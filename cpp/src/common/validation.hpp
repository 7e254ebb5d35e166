#pragma once
// Input checks shared by the kernels. Messages start with the argument's name so that the
// Python layer can pass them on unchanged.
#include <morphomap/errors.hpp>
#include <morphomap/laplace.hpp>
#include <morphomap/types.hpp>

#include <string>

namespace morphomap::detail {

[[noreturn]] void invalid(const char* name, const std::string& problem);

// Every coordinate finite.
void require_finite(const Points2Ref& points, const char* name);

// Lines origin + t * direction for a line query (2D or 3D; finiteness is checked by the caller):
// as many directions as origins, none of them the zero vector.
template <class PointsRef>
void require_directions(const PointsRef& origins, const PointsRef& directions) {
  if (origins.rows() != directions.rows()) {
    invalid("directions",
            "has " + std::to_string(directions.rows()) + " rows but origins has " + std::to_string(origins.rows()));
  }
  for (Index i = 0; i < directions.rows(); ++i) {
    if (!(directions.row(i).cwiseAbs().maxCoeff() > 0)) {
      invalid("directions", "row " + std::to_string(i) + " is the zero vector");
    }
  }
}

// Points that take part: a closed curve whose last point repeats its first drops the last.
Index curve_size(const Points2Ref& points, bool closed);

// Finite, at least 2 (open) or 3 (closed) points, and a non-zero length. Returns curve_size.
Index require_curve(const Points2Ref& points, bool closed, const char* name);

// The curve without exact consecutive repeats (nor a closing repeat when closed), checked to
// still have enough points.
Points2 without_repeats(const Points2Ref& points, bool closed, const char* name);
// without_repeats for a curve that passed require_curve already.
Points2 drop_repeats(const Points2Ref& points, bool closed, const char* name);

// A closed curve (as checked by require_curve) whose area is not (nearly) zero against the square
// of its length: no orientation to trust, no region to mesh otherwise.
void require_area(const Points2Ref& points, const char* name);

// A closed curve without consecutive repeats (without_repeats), and its orientation in `turn`
// (+1 counter-clockwise, -1 clockwise): InvalidInput naming `name` where it encloses exactly
// zero area and so has none.
Points2 oriented_closed_curve(const Points2Ref& points, const char* name, int& turn);

// require_curve, then: one loop (no point repeated apart from consecutive repeats, as when two
// contours are concatenated) and no self-intersection, each with a message that gives the count
// and where. Returns curve_size.
Index require_simple_curve(const Points2Ref& points, bool closed, const char* name);

// The curve (as checked by require_curve), with consecutive repeats dropped, meets itself:
// InvalidInput naming `name`, with the number of pairs of segments that meet and the first of them.
void require_no_self_intersection(const Points2Ref& points, bool closed, const char* name);

// A closed surface's signed volume (check_closed_surface) is positive: its faces face outwards.
// Mapping and quality need that (an inward surface would fold every triangle).
void require_outward(double volume, const char* name);

// Whether that volume is more than rounding against the surface's size: faces that enclose no
// volume (two sheets on each other) leave 3D diffusion no region to mesh.
bool encloses_volume(double volume, const Points3Ref& vertices);
// InvalidInput "name: encloses no volume" unless encloses_volume; diffusion's rule, checked at the
// entries that run it (map_surfaces with "diffusion", solve_diffusion_3d).
void require_volume(double volume, const Points3Ref& vertices, const char* name);

// A contact tolerance (CurveMappingOptions::contact_tolerance) is finite; negative asks for the default.
void require_contact_tolerance(double value);

// The mesh_size option of every kernel that meshes a region (2D and 3D diffusion, map_surfaces,
// extend): a finite length >= 0, where 0 asks for the kernel's own size. One rule, one message.
void require_mesh_size(double value);

// A diffusion mesh size (require_mesh_size) and a mesh fraction > 0, both finite.
void require_diffusion_options(const DiffusionOptions& options);

// Number of worker threads the kernels use.
int thread_count();

}  // namespace morphomap::detail
