// A closed surface checked and indexed once (see prepared_surface.hpp).
#include <morphomap/prepared_surface.hpp>

#include "common/validation.hpp"

namespace morphomap {

namespace {

// The check runs before anything is copied or indexed.
const Points3Ref& checked(const Points3Ref& vertices, const FacesRef& faces, const char* name) {
  detail::require_outward(check_closed_surface(vertices, faces, name), name);
  return vertices;
}

}  // namespace

PreparedSurface::PreparedSurface(const Points3Ref& vertices, const FacesRef& faces, const char* name)
    : vertices_(checked(vertices, faces, name)), faces_(faces), index_(vertices_, faces_) {}

}  // namespace morphomap
