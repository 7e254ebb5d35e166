#include "diffusion/untangle.hpp"

#include "common/interrupt_check.hpp"

#include <CGAL/Gmpzf.h>
#include <CGAL/QP_functions.h>
#include <CGAL/QP_models.h>

#include <Eigen/LU>

#include <algorithm>
#include <cmath>
#include <limits>
#include <set>

namespace morphomap::detail {
namespace {

template <class Points, class Cells>
double measure(const Points& x, const Cells& cells, Index c) {
  constexpr int D = Points::ColsAtCompileTime;
  Eigen::Matrix<double, D, D> edges;
  for (int i = 0; i < D; ++i) edges.col(i) = (x.row(cells(c, i + 1)) - x.row(cells(c, 0))).transpose();
  return edges.determinant() / (D == 2 ? 2.0 : 6.0);
}

// A star's cells turned over (or flattened) and the smallest ratio among them all.
struct StarState {
  Index inverted = 0;
  double smallest = std::numeric_limits<double>::infinity();
  // Better: fewer inverted cells, or as many and a larger smallest ratio.
  bool better_than(const StarState& other) const {
    return inverted < other.inverted || (inverted == other.inverted && smallest > other.smallest);
  }
};

template <class Points, class Cells>
StarState star_state(const Points& rest, const Points& moved, const Cells& cells, const std::vector<Index>& star) {
  StarState state;
  for (const Index c : star) {
    const double ratio = measure(moved, cells, c) / measure(rest, cells, c);
    state.inverted += !(ratio > 0);
    state.smallest = std::min(state.smallest, ratio);
  }
  return state;
}

// Moves node v to the point of the box around it that maximises the smallest area (volume) ratio
// of its cells; keeps it where it is unless that leaves fewer of them inverted, or as many and a
// larger smallest ratio (where a boundary fold keeps one cell inverted, the best smallest ratio
// could turn others over). Returns whether it moved.
template <class Points, class Cells>
bool improve_node(const Points& rest, Points& moved, const Cells& cells, const std::vector<Index>& star, Index v) {
  constexpr int D = Points::ColsAtCompileTime;
  const Eigen::Matrix<double, 1, D> at = moved.row(v);
  double reach = 0.0;
  for (const Index c : star) {
    for (int i = 0; i <= D; ++i) reach = std::max(reach, (moved.row(cells(c, i)) - at).norm());
  }
  if (!(reach > 0)) return false;
  // The variables: the offset d of the node (D) and the smallest ratio t. Each cell c of the
  // star: ratio(d) = (m_c + g_c . d) / rest_c >= t, written -g_c . d / rest_c + t <= m_c / rest_c.
  CGAL::Quadratic_program<double> lp(CGAL::SMALLER, false, 0, false, 0);
  int row = 0;
  for (const Index c : star) {
    const double before = measure(rest, cells, c), now = measure(moved, cells, c);
    for (int a = 0; a < D; ++a) {
      // The measure is linear in one corner: its slope along axis a, exact to rounding.
      moved(v, a) += reach;
      const double slope = (measure(moved, cells, c) - now) / reach;
      moved(v, a) = at(a);
      lp.set_a(a, row, -slope / before);
    }
    lp.set_a(D, row, 1.0);
    lp.set_b(row, now / before);
    ++row;
  }
  for (int a = 0; a < D; ++a) {
    lp.set_l(a, true, -reach);
    lp.set_u(a, true, reach);
  }
  lp.set_c(D, -1.0);  // maximise t
  const auto solution = CGAL::solve_linear_program(lp, CGAL::Gmpzf());
  if (!solution.is_optimal()) return false;
  const StarState before = star_state(rest, moved, cells, star);
  auto value = solution.variable_values_begin();
  for (int a = 0; a < D; ++a, ++value) moved(v, a) = at(a) + CGAL::to_double(*value);
  if (moved.row(v).allFinite() && star_state(rest, moved, cells, star).better_than(before)) return true;
  moved.row(v) = at;
  return false;
}

template <class Points, class Cells>
Index untangle_mesh(const Points& rest, Points& moved, const Cells& cells, const std::vector<char>& fixed, int sweeps) {
  std::vector<std::vector<Index>> stars(rest.rows());  // the cells of each node
  for (Index c = 0; c < cells.rows(); ++c) {
    for (Index i = 0; i < cells.cols(); ++i) stars[cells(c, i)].push_back(c);
  }
  Index moved_count = 0;
  int ring = 0;  // how far beyond the inverted cells' corners the nodes to move reach
  constexpr int kRings = 2;
  for (int sweep = 0; sweep < sweeps; ++sweep) {
    check_interrupt();
    std::set<Index> nodes;
    for (Index c = 0; c < cells.rows(); ++c) {
      if (measure(moved, cells, c) / measure(rest, cells, c) > 0) continue;
      for (Index i = 0; i < cells.cols(); ++i) nodes.insert(cells(c, i));
    }
    if (nodes.empty()) break;
    // Where the corners alone cannot move apart (a cluster of inverted cells), their neighbours
    // make room.
    for (int r = 0; r < ring; ++r) {
      std::set<Index> grown = nodes;
      for (const Index v : nodes) {
        for (const Index c : stars[v]) {
          for (Index i = 0; i < cells.cols(); ++i) grown.insert(cells(c, i));
        }
      }
      nodes.swap(grown);
    }
    Index moved_now = 0;
    for (const Index v : nodes) {
      if (!fixed[v]) moved_now += improve_node(rest, moved, cells, stars[v], v);
    }
    moved_count += moved_now;
    if (moved_now == 0) {
      if (ring == kRings) break;
      ++ring;
    }
  }
  return moved_count;
}

}  // namespace

Index untangle(const Points2& rest, Points2& moved, const Faces& cells, const std::vector<char>& fixed, int sweeps) {
  return untangle_mesh(rest, moved, cells, fixed, sweeps);
}

Index untangle(const Points3& rest, Points3& moved, const Tetrahedra& cells, const std::vector<char>& fixed,
               int sweeps) {
  return untangle_mesh(rest, moved, cells, fixed, sweeps);
}

}  // namespace morphomap::detail
