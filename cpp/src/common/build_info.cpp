#include <morphomap/build_info.hpp>

#include "common/validation.hpp"

#include <CGAL/version_macros.h>
#include <embree3/rtcore.h>
#include <tbb/version.h>
#include <Eigen/Core>

namespace morphomap {

namespace {
std::string dotted(int a, int b, int c) {
  return std::to_string(a) + "." + std::to_string(b) + "." + std::to_string(c);
}
}  // namespace

BuildInfo build_info() {
  BuildInfo info;
  info.version = MORPHOMAP_VERSION;
  info.cgal = CGAL_VERSION_STR;
  info.embree = RTC_VERSION_STRING;
  info.eigen = dotted(EIGEN_WORLD_VERSION, EIGEN_MAJOR_VERSION, EIGEN_MINOR_VERSION);
  info.tbb = TBB_VERSION_STRING;
  info.threads = detail::thread_count();
  return info;
}

}  // namespace morphomap
