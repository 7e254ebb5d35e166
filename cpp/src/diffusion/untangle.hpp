#pragma once
// Untangling the cells a mesh motion turns over, by moving their free corners alone: each such
// node goes to the point of its star that maximises the smallest ratio of a cell's signed area
// (volume) after and before the motion (a linear program: that measure is linear in one corner).
#include <morphomap/types.hpp>

#include <vector>

namespace morphomap::detail {

// rest: the mesh as given; moved: its nodes after the motion, updated in place; fixed: the nodes
// that must not move (the boundary). Sweeps over the free corners of the cells still inverted
// (and, once those are stuck, over their neighbours up to two rings out) until none is inverted
// or nothing moves (at most `sweeps`); a move never leaves more cells inverted. Returns the
// number of moves.
Index untangle(const Points2& rest, Points2& moved, const Faces& cells, const std::vector<char>& fixed, int sweeps);
Index untangle(const Points3& rest, Points3& moved, const Tetrahedra& cells, const std::vector<char>& fixed,
               int sweeps);

}  // namespace morphomap::detail
