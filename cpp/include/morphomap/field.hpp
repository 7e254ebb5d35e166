#pragma once
// The result of a mapping: one displacement vector per start point.
#include <morphomap/types.hpp>

#include <cstdint>
#include <string>
#include <vector>

namespace morphomap {

// The basic algorithm that produced a vector, and whether it ran backwards (from C2 to C1, the
// paper's reverse mapping, then flipped).
enum class Method : std::int8_t {
  minimal_distance = 0,
  normal = 1,
  diffusion = 2,
  uniform = 3,
  reverse_minimal_distance = 4,
  reverse_normal = 5,
  reverse_diffusion = 6,
  reverse_uniform = 7,
  optimal = 8,  // beyond the paper: the order-preserving matching (optimal.hpp)
  reverse_optimal = 9,
};
constexpr int kMethodCount = 10;

// The label's name, from the method table (kMethodTable in mapping.hpp): its algorithm's name,
// with "reverse_" before it for a vector found from C2.
std::string method_name(Method method);

// The same algorithm run the other way (the table's other label): normal <-> reverse_normal, ...
Method reversed(Method method);

// Vectors starts[i] -> ends[i] from C1 to C2, in the order of the points of the curve the
// algorithm mapped from. A row whose algorithm found no target is NaN in ends (and, for a
// reverse mapping, in starts too).
struct DisplacementField2 {
  Points2 starts;
  Points2 ends;
  std::vector<Method> methods;

  Index size() const { return starts.rows(); }
  bool valid(Index i) const { return starts.row(i).allFinite() && ends.row(i).allFinite(); }
};

// The same for surfaces: start points are the vertices of the source surface, and faces their
// connectivity (so that quality can be measured).
struct DisplacementField3 {
  Points3 starts;
  Points3 ends;
  Faces faces;
  std::vector<Method> methods;

  Index size() const { return starts.rows(); }
  bool valid(Index i) const { return starts.row(i).allFinite() && ends.row(i).allFinite(); }
};

}  // namespace morphomap
