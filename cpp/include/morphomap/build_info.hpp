#pragma once
// What this build of morphomap was compiled against, for bug reports.
#include <string>

namespace morphomap {

struct BuildInfo {
  std::string version;
  std::string cgal;
  std::string embree;
  std::string eigen;
  std::string tbb;
  int threads;  // worker threads the kernels will use
};

BuildInfo build_info();

}  // namespace morphomap
