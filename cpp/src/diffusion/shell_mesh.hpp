#pragma once
// The region between two closed surfaces as a tetrahedral mesh (CGAL's Mesh_3). Kept small and
// stable: the translation unit behind it compiles for minutes.
#include <morphomap/types.hpp>

#include <atomic>
#include <memory>
#include <vector>

namespace morphomap::detail {

// A surface in CGAL's form (surfaces/surface_mesh.hpp), converted once and handed to each of the
// calls below that needs it.
class ClosedSurface {
 public:
  // Throws GeometryError if the faces do not form a manifold triangle mesh.
  ClosedSurface(const Points3Ref& vertices, const FacesRef& faces);
  ~ClosedSurface();
  ClosedSurface(const ClosedSurface&) = delete;
  ClosedSurface& operator=(const ClosedSurface&) = delete;

  struct Mesh;  // the CGAL surface mesh (shell_mesh.cpp)
  const Mesh& mesh() const { return *mesh_; }

  // Whether classify_nesting has found it free of self-intersections: a surface held for several
  // pairs (PreparedSurface, a series' frame) is tested once, not once per pair and stage.
  bool known_simple() const { return known_simple_.load(std::memory_order_relaxed); }
  void mark_simple() const { known_simple_.store(true, std::memory_order_relaxed); }

 private:
  std::unique_ptr<Mesh> mesh_;
  mutable std::atomic<bool> known_simple_{false};  // set once; a race only repeats the test
};

// How two closed, outward-oriented surfaces lie relative to each other. Throws InvalidInput if
// either intersects itself (a surface already known_simple is not tested again).
enum class Nesting { source_inside, target_inside, disjoint, crossing };
Nesting classify_nesting(const ClosedSurface& source, const ClosedSurface& target);
// The nesting of the pair taken the other way round (target as source).
inline Nesting swapped(Nesting nesting) {
  if (nesting == Nesting::source_inside) return Nesting::target_inside;
  if (nesting == Nesting::target_inside) return Nesting::source_inside;
  return nesting;
}

// For each query point: whether it lies inside the closed, outward-oriented surface (exact
// predicates, so points within rounding of the surface are still told apart); on it counts as inside.
std::vector<char> inside_surface(const ClosedSurface& surface, const Points3Ref& queries);

struct ShellMeshCriteria {
  // Target edge length: source_size + grading * (distance to the source surface) near the source,
  // likewise near the target, the smaller of the two, never above cell_size.
  double source_size = 0.0;
  double target_size = 0.0;
  double grading = 0.0;
  double cell_size = 0.0;
  double facet_distance = 0.0;  // largest distance between the mesh boundary and the surfaces
  bool exude = true;            // remove slivers after refinement
  int seed = 0;                 // of the mesher's random choices (another seed, another mesh)
  // Mesh_3's parallel mode on all cores (nested surfaces only; crossing ones mesh sequentially):
  // faster, but the mesh differs from run to run.
  bool parallel = false;
  // Coarser away from a region (nested surfaces only: auto's local diffusion). Farther than
  // focus_radius from every focus point, the sizes above and facet_distance grow by focus_grading
  // times the distance beyond it, up to `coarsening` times. No focus points: as above everywhere.
  Points3 focus;
  double focus_radius = 0.0;
  double focus_grading = 0.0;
  double coarsening = 1.0;
};

enum FacePatch : signed char { interior_face = 0, source_face = 1, target_face = 2, other_face = -1 };

struct ShellMesh {
  Points3 vertices;
  Tetrahedra tetrahedra;  // positively oriented
  Tetrahedra neighbours;  // neighbours(t, i): the tetrahedron across the face opposite
                          // vertex i of t, or -1 on the boundary
  Eigen::Matrix<signed char, Eigen::Dynamic, 4, Eigen::RowMajor> patches;  // FacePatch of each face
};

// Both surfaces closed, consistently oriented outwards (positive volume) and not crossing; inner
// and outer as classify_nesting found them. Throws GeometryError if Mesh_3 fails.
ShellMesh mesh_shell(const ClosedSurface& source, const ClosedSurface& target, bool source_inside,
                     const ShellMeshCriteria& criteria);

// The symmetric difference of two crossing closed surfaces: each surface cut along the curves
// where they cross (CGAL's corefinement) into patches that lie inside or outside the other. The
// pieces are S1 \ S2 (between the parts of S1 outside S2 and of S2 inside S1) and S2 \ S1. Where
// the surfaces coincide, facing the same way, the pieces pinch to the patch's rim: it bounds neither.
class CrossingRegion {
 public:
  // Both surfaces closed, consistently oriented outwards, free of self-intersections and crossing
  // (classify_nesting). Throws InvalidInput if the two press against each other over a patch
  // (coincide facing opposite ways).
  CrossingRegion(const ClosedSurface& source, const ClosedSurface& target);
  ~CrossingRegion();
  CrossingRegion(const CrossingRegion&) = delete;
  CrossingRegion& operator=(const CrossingRegion&) = delete;

  double volume() const;  // of all the pieces together
  // Tetrahedra of every piece (subdomains 1: S1 \ S2 and 2: S2 \ S1); the curves where the
  // surfaces cross are protected as mesh edges. Throws GeometryError if Mesh_3 fails.
  ShellMesh mesh(const ShellMeshCriteria& criteria) const;

 private:
  struct Patches;
  std::unique_ptr<Patches> patches_;
};

}  // namespace morphomap::detail
