#pragma once
// The special values the kernels write where there is no answer (NaN rows) or no bound yet.
#include <limits>

namespace morphomap::detail {

constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr double kInf = std::numeric_limits<double>::infinity();

// -1, 0 or +1.
constexpr int sign(double x) { return (x > 0) - (x < 0); }

}  // namespace morphomap::detail
