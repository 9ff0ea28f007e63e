// Vectors of 32-bit indices beside DoubleLanes.h's doubles, one index a lane, and the
// gathers through them, on AVX2 (four lanes, namespace avx2) and AVX-512 (eight, namespace
// avx512) behind one set of names: the surface lanes (SurfaceLanes-inl.h) are written once
// over them. A gathered float becomes a double exactly, so both widths give the same bits.
//
// The gathers are plain loads, one a lane, put together in registers: on current x86
// cores the gather instructions (vpgatherdq) cost more than the separate loads they
// replace when, as here, the data is mostly in L1.
#pragma once

#include "cpu/simd/DoubleLanes.h"

#if VAO_HAVE_AVX2_TARGET
#include <immintrin.h>

#include <cstdint>

namespace vao
{
namespace detail
{
/// The 8 bytes at byte offsets Scale * i and Scale * j of base, in one vector (SSE2: the
/// gathers of both widths inline it).
template <int Scale>
VAO_ALWAYS_INLINE __m128i loadPairs(const float* base, std::int32_t i, std::int32_t j)
{
  const char* bytes = reinterpret_cast<const char*>(base);
  return _mm_unpacklo_epi64(
    _mm_loadl_epi64(reinterpret_cast<const __m128i*>(bytes + static_cast<std::int64_t>(i) * Scale)),
    _mm_loadl_epi64(
      reinterpret_cast<const __m128i*>(bytes + static_cast<std::int64_t>(j) * Scale)));
}

namespace avx2
{
using Idx = __m128i;
#define VAO_LANES VAO_AVX2_HELPER

VAO_LANES Idx indices(std::int64_t x)
{
  return _mm_set1_epi32(static_cast<int>(x));
}
VAO_LANES Idx add(Idx a, Idx b)
{
  return _mm_add_epi32(a, b);
}
VAO_LANES Idx mul(Idx a, Idx b)
{
  return _mm_mullo_epi32(a, b);
}
VAO_LANES Idx min(Idx a, Idx b)
{
  return _mm_min_epi32(a, b);
}
/// x / 8 and x % 8 of non-negative indices (a tile and the place within it).
VAO_LANES Idx eighth(Idx x)
{
  return _mm_srli_epi32(x, 3);
}
VAO_LANES Idx remainderOfEight(Idx x)
{
  return _mm_and_si128(x, _mm_set1_epi32(7));
}
/// Truncation of doubles in [0, 2^31) and back.
VAO_LANES Idx truncate(D u)
{
  return _mm256_cvttpd_epi32(u);
}
VAO_LANES D toDouble(Idx x)
{
  return _mm256_cvtepi32_pd(x);
}
/// x where m, else 0.
VAO_LANES Idx onlyWhere(Mask m, Idx x)
{
  // The 64-bit lane masks narrowed to 32 bits.
  const __m256i wide = _mm256_castpd_si256(m);
  const __m128i narrow = _mm256_castsi256_si128(
    _mm256_permutevar8x32_epi32(wide, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7)));
  return _mm_and_si128(narrow, x);
}
VAO_LANES void storeIndices(std::int32_t* to, Idx x)
{
  _mm_storeu_si128(reinterpret_cast<__m128i*>(to), x);
}
VAO_LANES Idx loadIndices(const std::int32_t* from)
{
  return _mm_loadu_si128(reinterpret_cast<const __m128i*>(from));
}
VAO_LANES Idx gather(const std::int32_t* base, Idx at)
{
  alignas(16) std::int32_t i[4];
  storeIndices(i, at);
  return _mm_setr_epi32(base[i[0]], base[i[1]], base[i[2]], base[i[3]]);
}
/// The floats base[at[k]].
VAO_LANES D gatherFloats(const float* base, Idx at)
{
  alignas(16) std::int32_t i[4];
  storeIndices(i, at);
  return _mm256_cvtps_pd(_mm_setr_ps(base[i[0]], base[i[1]], base[i[2]], base[i[3]]));
}
/// The float pairs at byte Scale * at[k] of base: first and second of each.
template <int Scale>
VAO_LANES void gatherPairs(const float* base, Idx at, D& first, D& second)
{
  alignas(16) std::int32_t i[4];
  storeIndices(i, at);
  const __m128i low = loadPairs<Scale>(base, i[0], i[1]);
  const __m128i high = loadPairs<Scale>(base, i[2], i[3]);
  const __m256i pairs = _mm256_inserti128_si256(_mm256_castsi128_si256(low), high, 1);
  const __m256 grouped =
    _mm256_permutevar8x32_ps(_mm256_castsi256_ps(pairs), _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7));
  first = _mm256_cvtps_pd(_mm256_castps256_ps128(grouped));
  second = _mm256_cvtps_pd(_mm256_extractf128_ps(grouped, 1));
}
#undef VAO_LANES
} // namespace avx2

namespace avx512
{
using Idx = __m256i;
#define VAO_LANES VAO_AVX512_HELPER

VAO_LANES Idx indices(std::int64_t x)
{
  return _mm256_set1_epi32(static_cast<int>(x));
}
VAO_LANES Idx add(Idx a, Idx b)
{
  return _mm256_add_epi32(a, b);
}
VAO_LANES Idx mul(Idx a, Idx b)
{
  return _mm256_mullo_epi32(a, b);
}
VAO_LANES Idx min(Idx a, Idx b)
{
  return _mm256_min_epi32(a, b);
}
VAO_LANES Idx eighth(Idx x)
{
  return _mm256_srli_epi32(x, 3);
}
VAO_LANES Idx remainderOfEight(Idx x)
{
  return _mm256_and_si256(x, _mm256_set1_epi32(7));
}
VAO_LANES Idx truncate(D u)
{
  return _mm512_cvttpd_epi32(u);
}
VAO_LANES D toDouble(Idx x)
{
  return _mm512_cvtepi32_pd(x);
}
VAO_LANES Idx onlyWhere(Mask m, Idx x)
{
  return _mm256_maskz_mov_epi32(m, x);
}
VAO_LANES void storeIndices(std::int32_t* to, Idx x)
{
  _mm256_storeu_si256(reinterpret_cast<__m256i*>(to), x);
}
VAO_LANES Idx loadIndices(const std::int32_t* from)
{
  return _mm256_loadu_si256(reinterpret_cast<const __m256i*>(from));
}
VAO_LANES Idx gather(const std::int32_t* base, Idx at)
{
  alignas(32) std::int32_t i[8];
  storeIndices(i, at);
  return _mm256_setr_epi32(
    base[i[0]], base[i[1]], base[i[2]], base[i[3]], base[i[4]], base[i[5]], base[i[6]], base[i[7]]);
}
VAO_LANES D gatherFloats(const float* base, Idx at)
{
  alignas(32) std::int32_t i[8];
  storeIndices(i, at);
  return _mm512_cvtps_pd(_mm256_setr_ps(base[i[0]], base[i[1]], base[i[2]], base[i[3]], base[i[4]],
    base[i[5]], base[i[6]], base[i[7]]));
}
template <int Scale>
VAO_LANES void gatherPairs(const float* base, Idx at, D& first, D& second)
{
  alignas(32) std::int32_t i[8];
  storeIndices(i, at);
  __m128i quarter[4];
  for (int q = 0; q < 4; ++q)
    quarter[q] = loadPairs<Scale>(base, i[2 * q], i[2 * q + 1]);
  const __m256i low = _mm256_inserti128_si256(_mm256_castsi128_si256(quarter[0]), quarter[1], 1);
  const __m256i high = _mm256_inserti128_si256(_mm256_castsi128_si256(quarter[2]), quarter[3], 1);
  const __m512i pairs = _mm512_inserti64x4(_mm512_castsi256_si512(low), high, 1);
  const __m512 grouped =
    _mm512_permutexvar_ps(_mm512_setr_epi32(0, 2, 4, 6, 8, 10, 12, 14, 1, 3, 5, 7, 9, 11, 13, 15),
      _mm512_castsi512_ps(pairs));
  first = _mm512_cvtps_pd(_mm512_castps512_ps256(grouped));
  second = _mm512_cvtps_pd(_mm512_extractf32x8_ps(grouped, 1));
}
#undef VAO_LANES
} // namespace avx512

} // namespace detail
} // namespace vao
#endif
