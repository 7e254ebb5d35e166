#pragma once
// Four floats at a time: SSE2 on x86-64 (part of the architecture: no run-time dispatch needed),
// plain arrays elsewhere, and the sort of four child keys the tree walks use.
#if defined(__SSE2__) || defined(_M_X64)
#include <emmintrin.h>
#define MORPHOMAP_SSE2 1
#endif

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

namespace morphomap::simd4 {

// Four floats: SSE2, or plain arrays where SSE2 is missing. A comparison gives a lane mask.
#ifdef MORPHOMAP_SSE2
struct F4 {
  __m128 v;
  static F4 load(const float* p) { return {_mm_load_ps(p)}; }
  static F4 all(float x) { return {_mm_set1_ps(x)}; }
  friend F4 operator+(F4 a, F4 b) { return {_mm_add_ps(a.v, b.v)}; }
  friend F4 operator-(F4 a, F4 b) { return {_mm_sub_ps(a.v, b.v)}; }
  friend F4 operator*(F4 a, F4 b) { return {_mm_mul_ps(a.v, b.v)}; }
  friend F4 operator&(F4 a, F4 b) { return {_mm_and_ps(a.v, b.v)}; }
  friend F4 operator|(F4 a, F4 b) { return {_mm_or_ps(a.v, b.v)}; }
  friend F4 abs(F4 a) { return {_mm_andnot_ps(_mm_set1_ps(-0.0f), a.v)}; }
  friend F4 max(F4 a, F4 b) { return {_mm_max_ps(a.v, b.v)}; }
  friend F4 le(F4 a, F4 b) { return {_mm_cmple_ps(a.v, b.v)}; }  // false for NaN
  friend int bits(F4 mask) { return _mm_movemask_ps(mask.v); }
};

// The four children as sort keys, farthest first: the bound (at least FLT_MIN, so that no key
// is subnormal, with its last two bits cleared, which only lowers it) with the lane in those
// bits; children not kept get 0, which sorts last. Positive floats order as their bits, so a
// min/max network sorts them (three rounds of two compare-exchanges). Written to out[0..3].
inline void sorted_keys(F4 bound, F4 keep, std::int32_t* out) {
  const __m128i lane = _mm_set_epi32(3, 2, 1, 0);
  const __m128i low = _mm_set1_epi32(3);
  const __m128i key0 = _mm_castps_si128(bound.v);
  const __m128i key = _mm_and_si128(_mm_castps_si128(keep.v), _mm_or_si128(_mm_andnot_si128(low, key0), lane));
  __m128 k = _mm_castsi128_ps(key);
  // (0 1) (2 3) -> [max01 max23 min01 min23]; again -> [max, ., ., min]; then the middle pair.
  for (int round = 0; round < 2; ++round) {
    const __m128 other = _mm_shuffle_ps(k, k, _MM_SHUFFLE(2, 3, 0, 1));
    k = _mm_shuffle_ps(_mm_max_ps(k, other), _mm_min_ps(k, other), _MM_SHUFFLE(2, 0, 2, 0));
  }
  const __m128 other = _mm_shuffle_ps(k, k, _MM_SHUFFLE(3, 1, 2, 0));
  k = _mm_shuffle_ps(_mm_max_ps(k, other), _mm_min_ps(k, other), _MM_SHUFFLE(3, 2, 1, 0));
  _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm_castps_si128(k));
}

// Four copies of a node index.
inline void store4(std::int32_t* out, std::int32_t x) {
  _mm_storeu_si128(reinterpret_cast<__m128i*>(out), _mm_set1_epi32(x));
}
#else
struct F4 {
  float v[4];
  static F4 load(const float* p) { return {{p[0], p[1], p[2], p[3]}}; }
  static F4 all(float x) { return {{x, x, x, x}}; }
  template <class Op>
  static F4 map(F4 a, F4 b, Op op) {
    return {{op(a.v[0], b.v[0]), op(a.v[1], b.v[1]), op(a.v[2], b.v[2]), op(a.v[3], b.v[3])}};
  }
  friend F4 operator+(F4 a, F4 b) {
    return map(a, b, [](float x, float y) { return x + y; });
  }
  friend F4 operator-(F4 a, F4 b) {
    return map(a, b, [](float x, float y) { return x - y; });
  }
  friend F4 operator*(F4 a, F4 b) {
    return map(a, b, [](float x, float y) { return x * y; });
  }
  friend F4 operator&(F4 a, F4 b) {
    return map(a, b, [](float x, float y) { return x != 0 && y != 0 ? 1.0f : 0.0f; });
  }
  friend F4 operator|(F4 a, F4 b) {
    return map(a, b, [](float x, float y) { return x != 0 || y != 0 ? 1.0f : 0.0f; });
  }
  friend F4 abs(F4 a) { return {{std::abs(a.v[0]), std::abs(a.v[1]), std::abs(a.v[2]), std::abs(a.v[3])}}; }
  friend F4 max(F4 a, F4 b) {
    return map(a, b, [](float x, float y) { return x > y ? x : y; });
  }
  friend F4 le(F4 a, F4 b) {
    return map(a, b, [](float x, float y) { return x <= y ? 1.0f : 0.0f; });
  }
  friend int bits(F4 mask) {
    return (mask.v[0] != 0) | (mask.v[1] != 0) << 1 | (mask.v[2] != 0) << 2 | (mask.v[3] != 0) << 3;
  }
};

inline void sorted_keys(F4 bound, F4 keep, std::int32_t* out) {
  for (int k = 0; k < 4; ++k) {
    std::memcpy(&out[k], &bound.v[k], sizeof(float));
    out[k] = keep.v[k] != 0 ? (out[k] & ~3) | k : 0;
  }
  std::sort(out, out + 4, [](std::int32_t x, std::int32_t y) { return x > y; });
}

inline void store4(std::int32_t* out, std::int32_t x) { std::fill(out, out + 4, x); }
#endif

inline int count_trailing_zeros(unsigned x) {  // x != 0
#if defined(__GNUC__) || defined(__clang__)
  return __builtin_ctz(x);
#else
  int n = 0;
  while (!(x >> n & 1u)) ++n;
  return n;
#endif
}

inline float key_bound(std::int32_t key) {
  float b;
  std::memcpy(&b, &key, sizeof b);
  return b;
}

}  // namespace morphomap::simd4
