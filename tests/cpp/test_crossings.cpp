// Crossings among segments. Random sets against an exact brute force are in tests/test_crossings.py.
#include <morphomap/crossings.hpp>
#include <morphomap/errors.hpp>

#include "check.hpp"
#include "curves/crossing_sweep.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <string>
#include <utility>
#include <vector>

using morphomap::count_crossings;
using morphomap::crossing_pairs;
using morphomap::Index;
using morphomap::InvalidInput;
using morphomap::Points2;

namespace {

using Pair = std::pair<Index, Index>;
using Segment = std::pair<std::pair<double, double>, std::pair<double, double>>;

std::vector<Pair> pairs_of(const std::vector<Segment>& segments) {
  const Index n = static_cast<Index>(segments.size());
  Points2 a(n, 2), b(n, 2);
  for (Index i = 0; i < n; ++i) {
    a.row(i) << segments[i].first.first, segments[i].first.second;
    b.row(i) << segments[i].second.first, segments[i].second.second;
  }
  const std::vector<Pair> pairs = crossing_pairs(a, b);
  CHECK(count_crossings(a, b) == static_cast<Index>(pairs.size()));
  // Small inputs are answered by the box search; the sweep must agree, and so must the test that
  // stops at the first crossing.
  CHECK(morphomap::detail::crossing_pairs_by_sweep(a, b) == pairs);
  CHECK(morphomap::detail::any_crossing(a, b) == !pairs.empty());
  return pairs;
}

// Whether the two segments count as crossing, asked both ways round and with either reversed.
bool crosses(Segment s, Segment t) {
  const bool answer = pairs_of({s, t}).size() == 1;
  const Segment rs{s.second, s.first}, rt{t.second, t.first};
  CHECK(pairs_of({t, s}).size() == (answer ? 1u : 0u));
  CHECK(pairs_of({rs, t}).size() == (answer ? 1u : 0u));
  CHECK(pairs_of({s, rt}).size() == (answer ? 1u : 0u));
  return answer;
}

void test_pairs() {
  CHECK(crosses({{0, 0}, {2, 2}}, {{0, 2}, {2, 0}}));   // an X
  CHECK(!crosses({{0, 0}, {1, 0}}, {{0, 1}, {1, 1}}));  // parallel
  CHECK(!crosses({{0, 0}, {1, 0}}, {{0, 0}, {0, 1}}));  // shared start
  CHECK(!crosses({{0, 0}, {1, 0}}, {{2, 1}, {1, 0}}));  // end of one is start of the other
  CHECK(crosses({{0, 0}, {2, 0}}, {{1, 0}, {1, 1}}));   // T-junction
  CHECK(crosses({{0, 0}, {2, 0}}, {{1, -1}, {1, 0}}));
  CHECK(!crosses({{0, 0}, {1, 0}}, {{1, 0}, {2, 0}}));   // collinear, end to end
  CHECK(!crosses({{0, 0}, {1, 0}}, {{2, 0}, {3, 0}}));   // collinear, apart
  CHECK(crosses({{0, 0}, {2, 0}}, {{1, 0}, {3, 0}}));    // collinear, overlapping
  CHECK(crosses({{0, 0}, {2, 0}}, {{0, 0}, {1, 0}}));    // shared start, overlapping
  CHECK(crosses({{0, 0}, {1, 1}}, {{0, 0}, {1, 1}}));    // identical
  CHECK(crosses({{0, 0}, {3, 0}}, {{1, 0}, {2, 0}}));    // one inside the other
  CHECK(!crosses({{0, 0}, {2, 0}}, {{0, 0}, {-1, 0}}));  // shared start, opposite ways
  // Zero-length segments: a point inside a segment crosses it, a point at an end does not.
  CHECK(crosses({{1, 1}, {1, 1}}, {{0, 0}, {2, 2}}));
  CHECK(!crosses({{0, 0}, {0, 0}}, {{0, 0}, {2, 2}}));
  CHECK(!crosses({{0, 0}, {0, 0}}, {{0, 0}, {0, 0}}));
  CHECK(!crosses({{1, 1}, {1, 1}}, {{0, 0}, {2, 3}}));
  // Exact: (1, 1/3 rounded down) lies below the segment to (3, 1); the next double above it does not.
  const double y = 1.0 / 3.0;
  CHECK(!crosses({{0, 0}, {3, 1}}, {{1, 0}, {1, y}}));
  CHECK(!crosses({{0, 0}, {3, 1}}, {{1, 0}, {1, std::nextafter(y, 0.0)}}));
  CHECK(crosses({{0, 0}, {3, 1}}, {{1, 0}, {1, std::nextafter(y, 1.0)}}));

  // Several at once: pairs are (i, j), i < j, in order; NaN rows are skipped.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const std::vector<Pair> p =
      pairs_of({{{0, 0}, {2, 2}}, {{nan, 0}, {2, 0}}, {{0, 2}, {2, 0}}, {{5, 5}, {6, 6}}, {{1, 0}, {1, 3}}});
  CHECK((p == std::vector<Pair>{{0, 2}, {0, 4}, {2, 4}}));
}

void test_fields() {
  // Radial vectors from a circle to a larger one never cross; swapping the ends of vectors
  // 2k and 2k + 1 makes each such pair cross and nothing else.
  const Index n = 2000;
  const double pi = std::acos(-1.0);
  Points2 a(n, 2), b(n, 2), c(n, 2);
  for (Index i = 0; i < n; ++i) {
    const double t = 2 * pi * i / n, u = 2 * pi * (i ^ 1) / n;
    a.row(i) << std::cos(t), std::sin(t);
    b.row(i) << 2 * std::cos(t), 2 * std::sin(t);
    c.row(i) << 2 * std::cos(u), 2 * std::sin(u);
  }
  CHECK(count_crossings(a, b) == 0);
  CHECK(count_crossings(a, c) == n / 2);
  const auto pairs = crossing_pairs(a, c);
  for (const Pair& q : pairs) CHECK(q.first % 2 == 0 && q.second == q.first + 1);

  // Many random segments: the count agrees with the list and the list is sorted and unique.
  std::mt19937 rng(5);
  std::uniform_int_distribution<int> grid(0, 20);
  Points2 s(3000, 2), e(3000, 2);
  for (Index i = 0; i < s.rows(); ++i) {
    s.row(i) << grid(rng), grid(rng);
    e.row(i) << s(i, 0) + grid(rng) % 4, s(i, 1) + grid(rng) % 4;
  }
  const auto many = crossing_pairs(s, e);
  CHECK(count_crossings(s, e) == static_cast<Index>(many.size()));
  for (std::size_t k = 0; k < many.size(); ++k) {
    CHECK(many[k].first < many[k].second);
    if (k > 0) CHECK(many[k - 1] < many[k]);
  }
}

// The exact O(n²) definition, for comparison with the sweep.
using Pt = std::pair<double, double>;
int orient_sign(Pt a, Pt b, Pt c) {
  // Small integers (and multiples of 1/4): exact in double.
  const double d = (b.first - a.first) * (c.second - a.second) - (b.second - a.second) * (c.first - a.first);
  return (d > 0) - (d < 0);
}
bool on_box(Pt a, Pt b, Pt c) {
  return std::min(a.first, b.first) <= c.first && c.first <= std::max(a.first, b.first) &&
         std::min(a.second, b.second) <= c.second && c.second <= std::max(a.second, b.second);
}
bool brute_cross(const Segment& s, const Segment& t) {
  const Pt a = s.first, b = s.second, c = t.first, d = t.second;
  const int o1 = orient_sign(a, b, c), o2 = orient_sign(a, b, d), o3 = orient_sign(c, d, a), o4 = orient_sign(c, d, b);
  const bool meet = (o1 * o2 < 0 && o3 * o4 < 0) || (o1 == 0 && on_box(a, b, c)) || (o2 == 0 && on_box(a, b, d)) ||
                    (o3 == 0 && on_box(c, d, a)) || (o4 == 0 && on_box(c, d, b));
  if (!meet) return false;
  for (const auto& [x, u] : {std::pair<Pt, Pt>{a, b}, std::pair<Pt, Pt>{b, a}}) {
    for (const auto& [y, w] : {std::pair<Pt, Pt>{c, d}, std::pair<Pt, Pt>{d, c}}) {
      if (x == y) {
        const double dot = (u.first - x.first) * (w.first - x.first) + (u.second - x.second) * (w.second - x.second);
        return orient_sign(x, u, w) == 0 && dot > 0;
      }
    }
  }
  return true;
}
bool finite(const Segment& s) {
  return std::isfinite(s.first.first) && std::isfinite(s.first.second) && std::isfinite(s.second.first) &&
         std::isfinite(s.second.second);
}
std::vector<Pair> brute_pairs(const std::vector<Segment>& segments) {
  std::vector<Pair> pairs;
  for (std::size_t i = 0; i < segments.size(); ++i) {
    for (std::size_t j = i + 1; j < segments.size(); ++j) {
      if (finite(segments[i]) && finite(segments[j]) && brute_cross(segments[i], segments[j])) {
        pairs.emplace_back(static_cast<Index>(i), static_cast<Index>(j));
      }
    }
  }
  return pairs;
}

void test_against_brute_force() {
  // CGAL 5.5's surface sweep fails on these four.
  const std::vector<Segment> four{{{0, 1}, {2, 3}}, {{3, 1}, {0, 3}}, {{3, 2}, {1, 2}}, {{1, 3}, {2, 1}}};
  CHECK(pairs_of(four) == brute_pairs(four));
  CHECK(!pairs_of(four).empty());

  // A fan of vectors into one point (and out of it), with repeated directions: no pair is a
  // crossing except vectors that overlap.
  std::mt19937 rng(11);
  std::vector<Segment> fan, out;
  for (int i = 0; i < 400; ++i) {
    const Pt p{double(int(rng() % 9)) - 4, double(int(rng() % 9)) - 4};
    fan.push_back({p, {0, 0}});
    out.push_back({{0, 0}, p});
  }
  CHECK(pairs_of(fan) == brute_pairs(fan));
  CHECK(pairs_of(out) == brute_pairs(out));

  // Many through one point, plus segments through the centre's row and column.
  std::vector<Segment> star;
  for (int i = 0; i < 60; ++i) {
    const double x = double(int(rng() % 7)), y = double(int(rng() % 7));
    star.push_back({{x, y}, {6 - x, 6 - y}});
    if (i % 5 == 0) star.push_back({{3, double(int(rng() % 7))}, {3, double(int(rng() % 7))}});
    if (i % 7 == 0) star.push_back({{double(int(rng() % 7)), 3}, {double(int(rng() % 7)), 3}});
    if (i % 11 == 0) star.push_back({{3, 3}, {3, 3}});
  }
  CHECK(pairs_of(star) == brute_pairs(star));

  // Random small grids: shared starts, points, NaN rows, vertical and horizontal segments,
  // collinear overlaps, and coordinates in quarters.
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (int round = 0; round < 1500; ++round) {
    const int n = 2 + int(rng() % 50), size = 2 + int(rng() % 7), mode = int(rng() % 4);
    const double scale = round % 3 == 0 ? 0.25 : 1.0;
    auto g = [&] { return scale * double(int(rng() % size)); };
    std::vector<Segment> segments;
    for (int i = 0; i < n; ++i) {
      Segment s{{g(), g()}, {g(), g()}};
      if (mode == 1) (rng() % 2 ? s.second.first : s.second.second) = rng() % 2 ? s.first.first : s.first.second;
      if (mode == 1 && rng() % 2) s.second.first = s.first.first;
      if (mode == 1 && rng() % 2) s.second.second = s.first.second;
      if (mode == 2) s.second = {scale * (size - 1) - s.first.first, scale * (size - 1) - s.first.second};
      if (mode == 3 && rng() % 2) s.first.second = s.first.first, s.second.second = s.second.first;
      if (i > 0 && rng() % 5 == 0) s.first = segments[rng() % i].first;
      if (i > 0 && rng() % 8 == 0) s.second = segments[rng() % i].second;
      if (rng() % 10 == 0) s.second = s.first;
      if (rng() % 20 == 0) s.second.second = nan;
      segments.push_back(s);
    }
    const std::vector<Pair> expected = brute_pairs(segments);
    const std::vector<Pair> got = pairs_of(segments);
    CHECK(got == expected);
    if (got != expected) break;
  }
}

void test_dense_parallel_field() {
  // 20000 parallel slanted vectors: every pair of boxes overlaps (2e8 candidates), so the box
  // search gives up and the sweep answers. Swapping the ends of vectors 2k and 2k + 1 for k < 10
  // makes exactly those ten pairs cross.
  const Index n = 20000;
  Points2 a(n, 2), b(n, 2);
  for (Index i = 0; i < n; ++i) {
    a.row(i) << 1e-4 * i, 0.0;
    b.row(i) << 1e-4 * i + 1.0, 1.0;
  }
  for (Index k = 0; k < 10; ++k) b.row(2 * k).swap(b.row(2 * k + 1));
  CHECK(count_crossings(a, b) == 10);
  const auto pairs = crossing_pairs(a, b);
  CHECK(pairs.size() == 10u);
  for (Index k = 0; k < Index(pairs.size()); ++k) CHECK(pairs[k] == Pair(2 * k, 2 * k + 1));
}

void test_validation() {
  const Points2 a = Points2::Zero(3, 2), b = Points2::Zero(2, 2);
  std::string message;
  try {
    crossing_pairs(a, b);
  } catch (const InvalidInput& e) {
    message = e.what();
  }
  CHECK(message.rfind("ends", 0) == 0);
  CHECK_THROWS(count_crossings(a, b), InvalidInput);
  CHECK(count_crossings(Points2(0, 2), Points2(0, 2)) == 0);
}

}  // namespace

int main() {
  test_pairs();
  test_fields();
  test_against_brute_force();
  test_dense_parallel_field();
  test_validation();
  TEST_MAIN_END();
}
