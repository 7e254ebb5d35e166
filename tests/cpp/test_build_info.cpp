#include <morphomap/morphomap.hpp>

#include "check.hpp"

int main() {
  const auto info = morphomap::build_info();
  CHECK(!info.version.empty());
  CHECK(info.cgal.rfind("5.", 0) == 0 || info.cgal.rfind("6.", 0) == 0);
  CHECK(info.embree.rfind("3.", 0) == 0 || info.embree.rfind("4.", 0) == 0);
  CHECK(info.eigen.rfind("3.", 0) == 0);
  CHECK(!info.tbb.empty());
  CHECK(info.threads >= 1);
  TEST_MAIN_END();
}
