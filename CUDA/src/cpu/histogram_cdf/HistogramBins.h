// The bins of values in Histogram CDF on the CPU: thresholdIndex (the number of thresholds
// below a value) for whole rows of voxels, the query's bin for one value.
#pragma once

#include "cpu/simd/CpuDispatch.h"

#if VAO_HAVE_AVX2_TARGET
#include <immintrin.h>
#endif

#include "vao/Estimators.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>
#include <vector>

namespace vao
{
namespace detail
{

/// Thresholds as keys a vector search compares values with: 16-bit integers for 8- and
/// 16-bit data, floats for float data, 64 of them in ascending order (padded with a key
/// no value is above). A value v of the data is above threshold t exactly when its key
/// is above t's key, so that the count of keys below v is thresholdIndex(v) less `offset`
/// (the thresholds below every value of the type).
template <class Key>
struct SearchKeys
{
  static constexpr int kKeys = 64;
  Key keys[kKeys];
  int offset = 0;

  /// thresholdIndex of a value of key k, one key at a time (a row's last values).
  int count(Key k) const
  {
    int below = this->offset;
    for (const Key key : this->keys)
      below += key < k ? 1 : 0;
    return below;
  }
};

/// The 16-bit key of an 8- or 16-bit integer: its value, less 2^15 for unsigned 16 bits
/// (the order kept in signed comparisons).
template <class T>
std::int16_t keyOf(T v)
{
  if constexpr (std::is_same<T, std::uint16_t>::value)
    return static_cast<std::int16_t>(static_cast<std::int32_t>(v) - 32768);
  else
    return static_cast<std::int16_t>(v);
}

#if VAO_HAVE_AVX2_TARGET
/// The bins of a row of n values by a branch-free binary search of a whole vector of
/// values at once, its probes looked up in the 64 keys held in registers (a permutation
/// across two or four vectors): seven steps for 32 16-bit or 16 float values, where a
/// table or a scalar search take a dependent load per value.
template <class T>
VAO_AVX512_TARGET void searchRowAvx512(const T* __restrict in, std::int64_t n,
  const SearchKeys<std::int16_t>& search, std::uint16_t* __restrict out)
{
  const __m512i low = _mm512_loadu_si512(search.keys), high = _mm512_loadu_si512(search.keys + 32);
  std::int64_t i = 0;
  for (; i + 32 <= n; i += 32)
  {
    __m512i v;
    if constexpr (sizeof(T) == 1)
    {
      const __m256i bytes = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(in + i));
      v = std::is_signed<T>::value ? _mm512_cvtepi8_epi16(bytes) : _mm512_cvtepu8_epi16(bytes);
    }
    else
    {
      v = _mm512_loadu_si512(in + i);
      if (!std::is_signed<T>::value)
        v = _mm512_xor_si512(v, _mm512_set1_epi16(-32768));
    }
    __m512i pos = _mm512_setzero_si512();
    for (int step = 32; step >= 1; step /= 2)
    {
      const __m512i probe =
        _mm512_permutex2var_epi16(low, _mm512_add_epi16(pos, _mm512_set1_epi16(step - 1)), high);
      pos =
        _mm512_mask_add_epi16(pos, _mm512_cmplt_epi16_mask(probe, v), pos, _mm512_set1_epi16(step));
    }
    const __m512i last = _mm512_permutex2var_epi16(low, pos, high);
    pos = _mm512_mask_add_epi16(pos, _mm512_cmplt_epi16_mask(last, v), pos, _mm512_set1_epi16(1));
    _mm512_storeu_si512(out + i, _mm512_add_epi16(pos, _mm512_set1_epi16(search.offset)));
  }
  for (; i < n; ++i)
    out[i] = static_cast<std::uint16_t>(search.count(keyOf(in[i])));
}

/// The float keys at indices `at` (0 to 63), from four vectors of 16.
VAO_AVX512_HELPER __m512 probeKeys(const __m512* table, __m512i at)
{
  const __m512 low = _mm512_permutex2var_ps(table[0], at, table[1]);
  const __m512 high = _mm512_permutex2var_ps(table[2], at, table[3]);
  return _mm512_mask_blend_ps(_mm512_test_epi32_mask(at, _mm512_set1_epi32(32)), low, high);
}

/// The same for floats: 16 values at once over keys in four vectors.
template <class T>
VAO_AVX512_TARGET void searchRowAvx512(const T* __restrict in, std::int64_t n,
  const SearchKeys<float>& search, std::uint16_t* __restrict out)
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
    pos = _mm512_add_epi32(pos, _mm512_set1_epi32(search.offset));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(out + i), _mm512_cvtepi32_epi16(pos));
  }
  for (; i < n; ++i)
    out[i] = static_cast<std::uint16_t>(search.count(in[i]));
}
#endif

/// Bin of a value (thresholdIndex): for rows of 8-bit, 16-bit and float voxels with at
/// most 64 thresholds in their type's range, searchRowAvx512; else a table over the
/// whole type for 8- and 16-bit integers, and a search that gives thresholdIndex's answer
/// without a branch per step (the thresholds padded with infinity to a power of two:
/// random values would mispredict half the steps).
template <class T>
class BinOf
{
public:
  BinOf(const std::vector<double>& thresholds, SimdTier simd, std::int64_t stride)
  {
    std::size_t padded = 1;
    while (padded < thresholds.size())
      padded *= 2;
    this->Padded.assign(padded, std::numeric_limits<double>::infinity());
    std::copy(thresholds.begin(), thresholds.end(), this->Padded.begin());
    this->Vector = VAO_HAVE_AVX2_TARGET && simd == SimdTier::Avx512 && this->placeKeys(thresholds);
    if (kTable && !(this->Vector && stride == 1))
    {
      const double lowest = static_cast<double>(std::numeric_limits<T>::lowest());
      this->Table.resize(std::size_t(1) << (8 * sizeof(T)));
      for (std::size_t i = 0; i < this->Table.size(); ++i)
      {
        this->Table[i] = static_cast<std::uint16_t>(thresholdIndex(
          lowest + static_cast<double>(i), thresholds.data(), static_cast<int>(thresholds.size())));
      }
    }
  }

  /// The bins of n values `stride` apart.
  void row(const T* in, std::int64_t stride, std::int64_t n, std::uint16_t* out) const
  {
#if VAO_HAVE_AVX2_TARGET
    if constexpr (kKeyed)
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
        out[i] = table[in[i * stride]];
    }
    else
    {
      for (std::int64_t i = 0; i < n; ++i)
        out[i] = static_cast<std::uint16_t>(this->search(static_cast<double>(in[i * stride])));
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
  static constexpr bool kKeyed = kTable || std::is_same<T, float>::value;
  typedef typename std::conditional<kTable, std::int16_t, float>::type Key;

  /// The keys of searchRowAvx512, when the thresholds allow them: those in the type's range
  /// number at most 64. For integers, t < v exactly when floor(t) < v; for floats, when
  /// the largest float not above t is below v.
  bool placeKeys(const std::vector<double>& thresholds)
  {
    if constexpr (!kKeyed)
      return false;
    else
    {
      int count = 0;
      for (const double t : thresholds)
      {
        Key key;
        if constexpr (kTable)
        {
          if (t < static_cast<double>(std::numeric_limits<T>::lowest()))
          {
            ++this->Keys.offset;
            continue;
          }
          if (t >= static_cast<double>(std::numeric_limits<T>::max()))
            break;
          key = keyOf(static_cast<T>(std::floor(t)));
        }
        else
        {
          key = static_cast<float>(t);
          if (static_cast<double>(key) > t)
            key = std::nextafter(key, -std::numeric_limits<float>::infinity());
        }
        if (count == SearchKeys<Key>::kKeys)
          return false;
        this->Keys.keys[count++] = key;
      }
      std::fill(this->Keys.keys + count, this->Keys.keys + SearchKeys<Key>::kKeys,
        std::numeric_limits<Key>::has_infinity ? std::numeric_limits<Key>::infinity()
                                               : std::numeric_limits<Key>::max());
      return true;
    }
  }

  bool Vector = false;
  SearchKeys<Key> Keys;
  std::vector<double> Padded;
  std::vector<std::uint16_t> Table;
};

} // namespace detail
} // namespace vao
