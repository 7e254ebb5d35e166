// monotone_match (the DP of method "optimal") on parallel lines, where the continuous minimiser of
// its energy solves a tridiagonal system: the DP's energy lies between the continuous minimum and
// the energy of that minimiser rounded to the target samples (a path the DP could have taken),
// and its ends lie near it (within 4 samples on the full grid, n = 50; through the
// coarse-to-fine band, n = 3000, the energy is flatter and they stay within 2.5% of the width).
#include <morphomap/errors.hpp>
#include <morphomap/optimal.hpp>

#include "check.hpp"

#include <cmath>
#include <vector>

using morphomap::GeometryError;
using morphomap::Index;
using morphomap::InvalidInput;
using morphomap::monotone_match;
using morphomap::Points2;
using morphomap::Vector;

namespace {

// Source: y = 0 from x = 0 to 1 through n equally spaced interior start points (rows 1..n).
// Target: y = 1 from x = 0 to `width`.
struct Lines {
  Points2 source, target;
  std::vector<Index> rows;
};

Lines lines(Index n, double width) {
  Lines l;
  l.source.resize(n + 2, 2);
  for (Index i = 0; i < n + 2; ++i) l.source.row(i) << static_cast<double>(i) / (n + 1), 0.0;
  l.target.resize(2, 2);
  l.target << 0.0, 1.0, width, 1.0;
  for (Index i = 1; i <= n; ++i) l.rows.push_back(i);
  return l;
}

// The energy of ends at x-positions t (t_0 = 0 and t_{n+1} = width implied): every start is within
// distance 1 of the target, so g^2 = 1 and |p_i - q_i|^2 = (t_i - x_i)^2 + 1.
double energy(const Vector& t, Index n, double width, double w) {
  const double h = 1.0 / (n + 1), alpha = width;
  double e = 0.0, before = 0.0;
  for (Index i = 1; i <= n + 1; ++i) {
    const double here = i <= n ? t[i - 1] : width;
    if (i <= n) e += (here - i * h) * (here - i * h) + 1.0;
    const double r = (here - before) / (alpha * h) - 1.0;
    e += w * r * r;
    before = here;
  }
  return e;
}

// The continuous minimiser: (1 + 2c) t_i - c t_{i-1} - c t_{i+1} = x_i, c = w / (alpha h)^2,
// solved by the Thomas algorithm.
Vector exact(Index n, double width, double w) {
  const double h = 1.0 / (n + 1), c = w / (width * h * width * h);
  Vector diag = Vector::Constant(n, 1.0 + 2.0 * c), rhs(n);
  for (Index i = 0; i < n; ++i) rhs[i] = (i + 1) * h;
  rhs[n - 1] += c * width;
  for (Index i = 1; i < n; ++i) {
    const double m = -c / diag[i - 1];
    diag[i] -= m * -c;
    rhs[i] -= m * rhs[i - 1];
  }
  Vector t(n);
  t[n - 1] = rhs[n - 1] / diag[n - 1];
  for (Index i = n - 2; i >= 0; --i) t[i] = (rhs[i] + c * t[i + 1]) / diag[i];
  return t;
}

void parallel_lines(Index n, double width, double w) {
  const Lines l = lines(n, width);
  const auto match = monotone_match(l.source, l.rows, l.target, w);
  const Vector best = exact(n, width, w);
  const double sample = width / match.samples;
  Vector rounded(n);
  for (Index i = 0; i < n; ++i) rounded[i] = sample * std::round(best[i] / sample);
  const double lower = energy(best, n, width, w), upper = energy(rounded, n, width, w);
  CHECK(match.energy >= lower - 1e-9 * lower);
  CHECK(match.energy <= upper + 1e-9 * upper);
  CHECK_NEAR(energy(match.arcs, n, width, w), match.energy, 1e-9 * match.energy);
  // The minimiser rounded is feasible but not optimal: the energy is flat along the path (a
  // sample more in one step, one less in another), more so the more steps there are, so the ends
  // stay near the minimiser rather than on it.
  const double off = (match.arcs - best).cwiseAbs().maxCoeff();
  CHECK(off <= (n <= 256 ? 4 * sample : 0.025 * width));
  CHECK(match.by_construction);  // the pieces and their end vectors bound a quadrilateral
  for (Index i = 0; i < n; ++i) {
    CHECK_NEAR(match.points(i, 0), match.arcs[i], 1e-12);
    CHECK_NEAR(match.points(i, 1), 1.0, 1e-12);
    if (i > 0) CHECK(match.arcs[i] > match.arcs[i - 1]);
  }
}

// Equal lengths: straight across is both nearest and uniform, so it is exact.
void straight_across() {
  const Index n = 40;
  const Lines l = lines(n, 1.0);
  const auto match = monotone_match(l.source, l.rows, l.target, 1.0);
  for (Index i = 0; i < n; ++i) CHECK_NEAR(match.arcs[i], (i + 1.0) / (n + 1), 1e-12);
  CHECK_NEAR(match.energy, static_cast<double>(n), 1e-9);
}

// Start points at the ends of the source are pinned to the ends of the target.
void pinned_ends() {
  const Lines l = lines(10, 2.0);
  std::vector<Index> all;
  for (Index i = 0; i < 12; ++i) all.push_back(i);
  const auto match = monotone_match(l.source, all, l.target, 1.0);
  CHECK_NEAR(match.arcs[0], 0.0, 0.0);
  CHECK_NEAR(match.arcs[11], 2.0, 1e-12);
  CHECK_NEAR(match.points(11, 0), 2.0, 0.0);
}

// Whole closed curves cut open (as method "optimal" passes them): concentric circles, cut at angle
// 0 on both. The region is the ring cut along the pinned first vector, nested and simple, so the
// matching is crossing-free by construction, and radial to within two target samples.
void cut_concentric_circles() {
  const Index n = 100, m = 300;
  auto circle = [](Index count, double radius) {
    Points2 c(count + 1, 2);
    for (Index i = 0; i <= count; ++i) {
      const double t = 2.0 * M_PI * static_cast<double>(i % count) / static_cast<double>(count);
      c.row(i) << radius * std::cos(t), radius * std::sin(t);
    }
    return c;
  };
  const Points2 source = circle(n, 1.0), target = circle(m, 2.0);
  std::vector<Index> rows(n);
  for (Index i = 0; i < n; ++i) rows[i] = i;
  const auto match = monotone_match(source, rows, target);
  CHECK(match.by_construction);
  const double sample = 2.0 * M_PI * 2.0 / static_cast<double>(match.samples);
  for (Index i = 0; i < n; ++i) CHECK_NEAR(match.arcs[i], 2.0 * 2.0 * M_PI * i / n, 2.0 * sample);
}

// The target run the other way: the vectors joining the pieces' ends cross, so there is no region
// and an order-preserving matching crosses itself: refused rather than returned.
void reversed_target_refused() {
  Lines l = lines(20, 1.0);
  l.target = Points2(l.target.colwise().reverse());
  CHECK_THROWS(monotone_match(l.source, l.rows, l.target, 1.0), GeometryError);
}

void bad_input() {
  const Lines l = lines(5, 1.0);
  CHECK_THROWS(monotone_match(l.source, {3, 2}, l.target, 1.0), InvalidInput);
  CHECK_THROWS(monotone_match(l.source, {1, 99}, l.target, 1.0), InvalidInput);
  CHECK_THROWS(monotone_match(l.source, l.rows, l.target, -1.0), InvalidInput);
  CHECK_THROWS(monotone_match(l.source, l.rows, l.target.topRows(1), 1.0), InvalidInput);
}

}  // namespace

int main() {
  straight_across();
  for (const double w : {0.0, 0.3, 1.0, 10.0}) parallel_lines(50, 2.0, w);
  parallel_lines(3000, 2.0, 1.0);
  parallel_lines(3000, 1.5, 0.3);
  pinned_ends();
  cut_concentric_circles();
  reversed_target_refused();
  bad_input();
  TEST_MAIN_END();
}
