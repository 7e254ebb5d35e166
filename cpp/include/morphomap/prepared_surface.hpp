#pragma once
// A closed surface checked and indexed once, for callers that use it in several pairs: in a time
// series frame k is the target of pair k - 1 and the source of pair k, and map_surfaces and
// quality would otherwise check it and build its Embree scene four times.
#include <morphomap/surface_queries.hpp>
#include <morphomap/types.hpp>

namespace morphomap {

class PreparedSurface {
 public:
  // Copies the surface. InvalidInput naming `name` where check_closed_surface fails, or when its
  // faces face inwards.
  PreparedSurface(const Points3Ref& vertices, const FacesRef& faces, const char* name);
  PreparedSurface(const PreparedSurface&) = delete;
  PreparedSurface& operator=(const PreparedSurface&) = delete;

  const Points3& vertices() const { return vertices_; }
  const Faces& faces() const { return faces_; }
  const SurfaceIndex& index() const { return index_; }

 private:
  Points3 vertices_;
  Faces faces_;
  SurfaceIndex index_;  // built from the copies above (declared after them)
};

}  // namespace morphomap
