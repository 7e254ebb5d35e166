#pragma once
// Queries of many points or lines against one closed triangle surface (Embree and CGAL behind it).
#include <morphomap/types.hpp>

#include <memory>

namespace morphomap {

// One answer per query; rows of a query that found nothing are NaN (faces: -1).
struct SurfaceHits {
  Points3 points;     // the point found on the surface
  Vector distances;   // closest points: Euclidean distance; lines: signed distance along the
                      // unit direction from the origin
  IndexVector faces;  // the triangle the point lies on
};

// A triangle surface prepared for many queries from all cores.
class SurfaceIndex {
 public:
  SurfaceIndex(const Points3Ref& vertices, const FacesRef& faces);
  ~SurfaceIndex();
  SurfaceIndex(SurfaceIndex&&) noexcept;
  SurfaceIndex& operator=(SurfaceIndex&&) noexcept;

  // Closest point on the surface to each query point (ties: the lowest face index, whatever the
  // traversal or thread count).
  SurfaceHits closest_points(const Points3Ref& queries) const;
  // The same within max_distance (>= 0; infinity: no limit): rows with no point of the surface
  // that close are NaN (faces: -1). Queries far from the surface cost next to nothing.
  SurfaceHits closest_points(const Points3Ref& queries, double max_distance) const;
  // For each line origin + t * direction, t of either sign, the intersection with the surface
  // nearest to the origin, refined in double precision on the hit triangle.
  SurfaceHits line_intersections(const Points3Ref& origins, const Points3Ref& directions) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

SurfaceHits closest_points(const Points3Ref& queries, const Points3Ref& vertices, const FacesRef& faces);
SurfaceHits line_intersections(const Points3Ref& origins, const Points3Ref& directions, const Points3Ref& vertices,
                               const FacesRef& faces);

// Unit normal at each vertex: the angle-weighted mean of the normals of the triangles around it;
// outward on a closed surface whose triangles are oriented consistently.
Points3 vertex_normals(const Points3Ref& vertices, const FacesRef& faces);

// Throws InvalidInput naming `name` unless the surface is closed, edge-manifold and consistently
// oriented, one connected component, with finite coordinates, valid indices, every vertex used and
// no zero-area face; returns its signed volume (positive when the normals point outwards).
// (A non-finite coordinate names "`name` vertices", an index out of range "`name` faces".)
double check_closed_surface(const Points3Ref& vertices, const FacesRef& faces, const char* name);

}  // namespace morphomap
