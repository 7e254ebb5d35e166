// Crossings among segments. Random sets against an exact brute force are in tests/test_crossings.py.
#include <morphomap/crossings.hpp>
#include <morphomap/errors.hpp>

#include "check.hpp"

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
  CHECK(crosses({{0, 0}, {2, 2}}, {{0, 2}, {2, 0}}));      // an X
  CHECK(!crosses({{0, 0}, {1, 0}}, {{0, 1}, {1, 1}}));     // parallel
  CHECK(!crosses({{0, 0}, {1, 0}}, {{0, 0}, {0, 1}}));     // shared start
  CHECK(!crosses({{0, 0}, {1, 0}}, {{2, 1}, {1, 0}}));     // end of one is start of the other
  CHECK(crosses({{0, 0}, {2, 0}}, {{1, 0}, {1, 1}}));      // T-junction
  CHECK(crosses({{0, 0}, {2, 0}}, {{1, -1}, {1, 0}}));
  CHECK(!crosses({{0, 0}, {1, 0}}, {{1, 0}, {2, 0}}));     // collinear, end to end
  CHECK(!crosses({{0, 0}, {1, 0}}, {{2, 0}, {3, 0}}));     // collinear, apart
  CHECK(crosses({{0, 0}, {2, 0}}, {{1, 0}, {3, 0}}));      // collinear, overlapping
  CHECK(crosses({{0, 0}, {2, 0}}, {{0, 0}, {1, 0}}));      // shared start, overlapping
  CHECK(crosses({{0, 0}, {1, 1}}, {{0, 0}, {1, 1}}));      // identical
  CHECK(crosses({{0, 0}, {3, 0}}, {{1, 0}, {2, 0}}));      // one inside the other
  CHECK(!crosses({{0, 0}, {2, 0}}, {{0, 0}, {-1, 0}}));    // shared start, opposite ways
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
  const std::vector<Pair> p = pairs_of({{{0, 0}, {2, 2}},
                                        {{nan, 0}, {2, 0}},
                                        {{0, 2}, {2, 0}},
                                        {{5, 5}, {6, 6}},
                                        {{1, 0}, {1, 3}}});
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
  test_validation();
  TEST_MAIN_END();
}
