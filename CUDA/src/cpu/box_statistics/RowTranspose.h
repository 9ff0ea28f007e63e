// The box extrema's x pass (BoxExtrema.h) runs its recurrence on vectors whose lanes are
// rows: it transposes kExtremumRows rows into lanes and its results back. For 16-bit
// voxels (CT scans) and 16 contiguous rows, whole 16 x 16 blocks go through AVX2
// registers (unless limitSimdTier caps the tier below AVX2); anything else element by
// element. Both give the same values.
#pragma once

#include "cpu/simd/CpuDispatch.h"

#include <cstdint>

#if VAO_HAVE_AVX2_TARGET
#include <immintrin.h>
#endif

namespace vao
{
namespace detail
{

#if VAO_HAVE_AVX2_TARGET
/// a[k] (16 rows of 16 values) becomes its transpose: a[i] holds element i of every row.
VAO_AVX2_HELPER void transpose16x16Epi16(__m256i* a)
{
  __m256i b[16], c[16], d[16];
  for (int i = 0; i < 8; ++i)
  {
    b[2 * i] = _mm256_unpacklo_epi16(a[2 * i], a[2 * i + 1]);
    b[2 * i + 1] = _mm256_unpackhi_epi16(a[2 * i], a[2 * i + 1]);
  }
  for (int i = 0; i < 4; ++i)
  {
    c[4 * i] = _mm256_unpacklo_epi32(b[4 * i], b[4 * i + 2]);
    c[4 * i + 1] = _mm256_unpackhi_epi32(b[4 * i], b[4 * i + 2]);
    c[4 * i + 2] = _mm256_unpacklo_epi32(b[4 * i + 1], b[4 * i + 3]);
    c[4 * i + 3] = _mm256_unpackhi_epi32(b[4 * i + 1], b[4 * i + 3]);
  }
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 4; ++j)
    {
      d[8 * i + 2 * j] = _mm256_unpacklo_epi64(c[8 * i + j], c[8 * i + j + 4]);
      d[8 * i + 2 * j + 1] = _mm256_unpackhi_epi64(c[8 * i + j], c[8 * i + j + 4]);
    }
  for (int j = 0; j < 8; ++j)
  {
    a[j] = _mm256_permute2x128_si256(d[j], d[j + 8], 0x20);
    a[j + 8] = _mm256_permute2x128_si256(d[j], d[j + 8], 0x31);
  }
}

/// out[i * 16 + k] = rows[k][i] for i in [0, blocks * 16): 16-bit values.
VAO_AVX2_INLINE void rowsToLanes16x16(const void* const* rows, std::int64_t blocks, void* out)
{
  for (std::int64_t b = 0; b < blocks; ++b)
  {
    __m256i a[16];
    for (int k = 0; k < 16; ++k)
      a[k] = _mm256_loadu_si256(
        reinterpret_cast<const __m256i*>(static_cast<const std::int16_t*>(rows[k]) + 16 * b));
    transpose16x16Epi16(a);
    for (int i = 0; i < 16; ++i)
      _mm256_storeu_si256(
        reinterpret_cast<__m256i*>(static_cast<std::int16_t*>(out) + 256 * b + 16 * i), a[i]);
  }
}

/// rows[k][o] = lanes[o * 16 + k] for o in [0, blocks * 16): 16-bit values.
VAO_AVX2_INLINE void lanesToRows16x16(const void* lanes, std::int64_t blocks, void* const* rows)
{
  for (std::int64_t b = 0; b < blocks; ++b)
  {
    __m256i a[16];
    for (int i = 0; i < 16; ++i)
      a[i] = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(
        static_cast<const std::int16_t*>(lanes) + 256 * b + 16 * i));
    transpose16x16Epi16(a);
    for (int k = 0; k < 16; ++k)
      _mm256_storeu_si256(
        reinterpret_cast<__m256i*>(static_cast<std::int16_t*>(rows[k]) + 16 * b), a[k]);
  }
}
#endif

/// Whether 16 contiguous rows of T go through the 16 x 16 block transposes: a caller with
/// fewer rows gains by padding them to 16.
template <class T>
bool transposesInBlocks()
{
#if VAO_HAVE_AVX2_TARGET
  return sizeof(T) == 2 && cpuSimdTier() >= SimdTier::Avx2;
#else
  return false;
#endif
}

/// lanes[i * m + k] = rows[k][i * stride] for k < m, i < span.
template <class T>
void rowsToLanes(
  const T* const* rows, std::int64_t m, std::int64_t stride, std::int64_t span, T* lanes)
{
  std::int64_t done = 0;
#if VAO_HAVE_AVX2_TARGET
  if (m == 16 && stride == 1 && transposesInBlocks<T>())
  {
    done = span / 16 * 16;
    rowsToLanes16x16(reinterpret_cast<const void* const*>(rows), span / 16, lanes);
  }
#endif
  for (std::int64_t k = 0; k < m; ++k)
    for (std::int64_t i = done; i < span; ++i)
      lanes[i * m + k] = rows[k][i * stride];
}

/// rows[k][o] = lanes[o * m + k] for k < m, o < n.
template <class T>
void lanesToRows(const T* lanes, std::int64_t m, std::int64_t n, T* const* rows)
{
  std::int64_t done = 0;
#if VAO_HAVE_AVX2_TARGET
  if (m == 16 && transposesInBlocks<T>())
  {
    done = n / 16 * 16;
    lanesToRows16x16(lanes, n / 16, reinterpret_cast<void* const*>(rows));
  }
#endif
  for (std::int64_t k = 0; k < m; ++k)
    for (std::int64_t o = done; o < n; ++o)
      rows[k][o] = lanes[o * m + k];
}

} // namespace detail
} // namespace vao
