// The bins of values in Histogram CDF on the CPU: thresholdIndex (the number of thresholds
// below a value) for whole rows of voxels, and for one query value.
#pragma once

#include "cpu/simd/CpuDispatch.h"

#if VAO_HAVE_AVX2_TARGET
#include <immintrin.h>
#endif

#include "vao/Estimators.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <type_traits>
#include <vector>

namespace vao
{
namespace detail
{

/// The thresholds as the float keys a vector search compares float values with: the
/// largest float not above each threshold, 64 in ascending order (padded with +infinity).
/// A float v is above threshold t exactly when it is above t's key, so the count of keys
/// below v is thresholdIndex(v).
struct FloatKeys
{
  static constexpr int kKeys = 64;
  float keys[kKeys];

  /// Keys for at most 64 thresholds; false for more.
  bool place(const std::vector<double>& thresholds)
  {
    if (thresholds.size() > std::size_t(kKeys))
      return false;
    std::fill(this->keys, this->keys + kKeys, std::numeric_limits<float>::infinity());
    const double largest = std::numeric_limits<float>::max();
    for (std::size_t k = 0; k < thresholds.size(); ++k)
    {
      // Beyond the floats: above or below every float value (no out-of-range conversion).
      const double t = thresholds[k];
      float key = t > largest ? std::numeric_limits<float>::max()
        : t < -largest        ? -std::numeric_limits<float>::infinity()
                              : static_cast<float>(t);
      if (static_cast<double>(key) > t)
        key = std::nextafter(key, -std::numeric_limits<float>::infinity());
      this->keys[k] = key;
    }
    return true;
  }

  /// thresholdIndex of one float (a row's last values).
  int count(float v) const
  {
    int below = 0;
    for (const float key : this->keys)
      below += key < v ? 1 : 0;
    return below;
  }
};

#if VAO_HAVE_AVX2_TARGET
/// The float keys at indices `at` (0 to 63), from four vectors of 16.
VAO_AVX512_HELPER __m512 probeKeys(const __m512* table, __m512i at)
{
  const __m512 low = _mm512_permutex2var_ps(table[0], at, table[1]);
  const __m512 high = _mm512_permutex2var_ps(table[2], at, table[3]);
  return _mm512_mask_blend_ps(_mm512_test_epi32_mask(at, _mm512_set1_epi32(32)), low, high);
}

/// The bins of a row of n floats, stored as O (8 or 16 bits), by a branch-free binary
/// search of 16 values at once, its probes looked up in the 64 keys held in four
/// registers: seven steps of a permutation and a comparison per vector, where a scalar
/// search takes six dependent loads per value.
template <class O>
VAO_AVX512_TARGET void searchRowAvx512(
  const float* __restrict in, std::int64_t n, const FloatKeys& search, O* __restrict out)
{
  __m512 table[4];
  for (int k = 0; k < 4; ++k)
    table[k] = _mm512_loadu_ps(search.keys + 16 * k);
  std::int64_t i = 0;
  for (; i + 16 <= n; i += 16)
  {
    const __m512 v = _mm512_loadu_ps(in + i);
    __m512i pos = _mm512_setzero_si512();
    for (int step = 32; step >= 1; step /= 2)
    {
      const __m512 p = probeKeys(table, _mm512_add_epi32(pos, _mm512_set1_epi32(step - 1)));
      pos = _mm512_mask_add_epi32(
        pos, _mm512_cmp_ps_mask(p, v, _CMP_LT_OQ), pos, _mm512_set1_epi32(step));
    }
    pos = _mm512_mask_add_epi32(
      pos, _mm512_cmp_ps_mask(probeKeys(table, pos), v, _CMP_LT_OQ), pos, _mm512_set1_epi32(1));
    if constexpr (sizeof(O) == 1)
      _mm_storeu_si128(reinterpret_cast<__m128i*>(out + i), _mm512_cvtepi32_epi8(pos));
    else
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + i), _mm512_cvtepi32_epi16(pos));
  }
  for (; i < n; ++i)
    out[i] = static_cast<O>(search.count(in[i]));
}
#endif

/// Bin of a value (thresholdIndex): a table over the whole type for 8- and 16-bit
/// integers (its part in use stays in the L1 cache on the data measured); for rows of
/// floats with at most 64 thresholds on AVX-512, searchRowAvx512; else a search that
/// gives thresholdIndex's answer without a branch per step (the thresholds padded with
/// infinity to a power of two: random values would mispredict half the steps).
template <class T>
class BinOf
{
public:
  BinOf(const std::vector<double>& thresholds, SimdTier simd)
  {
    std::size_t padded = 1;
    while (padded < thresholds.size())
      padded *= 2;
    this->Padded.assign(padded, std::numeric_limits<double>::infinity());
    std::copy(thresholds.begin(), thresholds.end(), this->Padded.begin());
    if constexpr (std::is_same<T, float>::value)
      this->Vector =
        VAO_HAVE_AVX2_TARGET && simd == SimdTier::Avx512 && this->Keys.place(thresholds);
    if constexpr (kTable)
    {
      // The values in ascending order, the count of thresholds below them walked along
      // (thresholdIndex of each, without a search per value of a 16-bit type).
      const double lowest = static_cast<double>(std::numeric_limits<T>::lowest());
      this->Table.resize(std::size_t(1) << (8 * sizeof(T)));
      std::size_t below = 0;
      for (std::size_t i = 0; i < this->Table.size(); ++i)
      {
        const double value = lowest + static_cast<double>(i);
        while (below < thresholds.size() && thresholds[below] < value)
          ++below;
        this->Table[i] = static_cast<std::uint16_t>(below);
      }
    }
  }

  /// The bins of n values `stride` apart, as O (8 bits where the bins fit).
  template <class O>
  void row(const T* in, std::int64_t stride, std::int64_t n, O* out) const
  {
#if VAO_HAVE_AVX2_TARGET
    if constexpr (std::is_same<T, float>::value)
      if (this->Vector && stride == 1)
      {
        searchRowAvx512(in, n, this->Keys, out);
        return;
      }
#endif
    if constexpr (kTable)
    {
      const std::uint16_t* table =
        this->Table.data() - std::int64_t(std::numeric_limits<T>::lowest());
      for (std::int64_t i = 0; i < n; ++i)
        out[i] = static_cast<O>(table[in[i * stride]]);
    }
    else
    {
      for (std::int64_t i = 0; i < n; ++i)
        out[i] = static_cast<O>(this->search(static_cast<double>(in[i * stride])));
    }
  }

  /// thresholdIndex(q): the number of thresholds below q (q not NaN).
  int search(double q) const
  {
    const double* first = this->Padded.data();
    std::size_t count = this->Padded.size();
    while (count > 1)
    {
      const std::size_t half = count / 2;
      first = first[half] < q ? first + half : first;
      count -= half;
    }
    return static_cast<int>(first - this->Padded.data()) + (*first < q ? 1 : 0);
  }

private:
  static constexpr bool kTable = std::is_integral<T>::value && sizeof(T) <= 2;
  bool Vector = false;
  FloatKeys Keys;
  std::vector<double> Padded;
  std::vector<std::uint16_t> Table;
};

} // namespace detail
} // namespace vao
