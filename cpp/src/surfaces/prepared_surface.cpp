// A closed surface checked and indexed once (see prepared_surface.hpp).
#include <morphomap/prepared_surface.hpp>

#include "common/validation.hpp"
#include "diffusion/shell_mesh.hpp"

namespace morphomap {

namespace {

// The check runs before anything is copied or indexed; returns the (positive) volume.
double checked_volume(const Points3Ref& vertices, const FacesRef& faces, const char* name) {
  const double volume = check_closed_surface(vertices, faces, name);
  detail::require_outward(volume, name);
  return volume;
}

}  // namespace

PreparedSurface::PreparedSurface(const Points3Ref& vertices, const FacesRef& faces, const char* name)
    : volume_(checked_volume(vertices, faces, name)),
      vertices_(vertices),
      faces_(faces),
      index_(vertices_, faces_),
      closed_(std::make_unique<const detail::ClosedSurface>(vertices_, faces_)) {}

PreparedSurface::~PreparedSurface() = default;

}  // namespace morphomap
