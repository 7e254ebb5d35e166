#pragma once
// A closed surface checked and indexed once, for callers that use it in several pairs: in a time
// series frame k is the target of pair k - 1 and the source of pair k, and map_surfaces and
// quality would otherwise check it and build its Embree scene four times.
#include <morphomap/surface_queries.hpp>
#include <morphomap/types.hpp>

#include <memory>

namespace morphomap {

namespace detail {
class ClosedSurface;  // the surface in CGAL's form (internal)
}  // namespace detail

class PreparedSurface {
 public:
  // Copies the surface. InvalidInput naming `name` where check_closed_surface fails, or when its
  // faces face inwards.
  PreparedSurface(const Points3Ref& vertices, const FacesRef& faces, const char* name);
  ~PreparedSurface();
  PreparedSurface(const PreparedSurface&) = delete;
  PreparedSurface& operator=(const PreparedSurface&) = delete;

  const Points3& vertices() const { return vertices_; }
  const Faces& faces() const { return faces_; }
  double volume() const { return volume_; }  // positive (the faces face outwards)
  const SurfaceIndex& index() const { return index_; }
  // Its CGAL form, which also remembers that the surface was found free of self-intersections,
  // so that a frame of a series is tested once, not as the target of one pair and the source
  // of the next.
  const detail::ClosedSurface& closed() const { return *closed_; }

 private:
  double volume_;
  Points3 vertices_;
  Faces faces_;
  SurfaceIndex index_;  // built from the copies above (declared after them)
  std::unique_ptr<const detail::ClosedSurface> closed_;
};

}  // namespace morphomap
