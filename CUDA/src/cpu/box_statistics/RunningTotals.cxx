#include "cpu/box_statistics/RunningTotals.h"

#include <type_traits>

#if VAO_HAVE_AVX2_TARGET
#include <immintrin.h>
#endif

namespace vao
{
namespace detail
{

namespace
{

/// One row from `begin` on, one value at a time (unsigned values wrap modulo their width).
template <class V>
void runningTotalsOfRow(V* a, std::int64_t begin, std::int64_t n)
{
  V total = begin > 0 ? a[begin - 1] : V(0);
  for (std::int64_t i = begin; i < n; ++i)
    a[i] = total += a[i];
}

/// From `begin` on, one value at a time; the running totals stay in registers (a and b may
/// alias as far as the compiler knows, so a[i] += a[i - 1] would reload each value just
/// stored).
template <class V>
void runningTotalsPlain(V* a, V* b, std::int64_t begin, std::int64_t n)
{
  if (begin >= n)
    return;
  if (!b)
  {
    runningTotalsOfRow(a, begin, n);
    return;
  }
  V totalA = begin > 0 ? a[begin - 1] : V(0);
  V totalB = begin > 0 ? b[begin - 1] : V(0);
  for (std::int64_t i = begin; i < n; ++i)
  {
    totalA += a[i];
    totalB += b[i];
    a[i] = totalA;
    b[i] = totalB;
  }
}

#if VAO_HAVE_AVX2_TARGET
/// The running totals within eight lanes: lane k gains lanes k - 1, k - 2, k - 4 in turn.
VAO_AVX512_TARGET inline __m512i scanLanes(__m512i x)
{
  const __m512i zero = _mm512_setzero_si512();
  x = _mm512_add_epi64(x, _mm512_alignr_epi64(x, zero, 7));
  x = _mm512_add_epi64(x, _mm512_alignr_epi64(x, zero, 6));
  return _mm512_add_epi64(x, _mm512_alignr_epi64(x, zero, 4));
}

/// 64-bit running totals four at a time: within each 128-bit half by a shifted add, then
/// the low half's total added to the high half.
VAO_AVX2_HELPER __m256i scanLanes(__m256i x)
{
  x = _mm256_add_epi64(x, _mm256_slli_si256(x, 8));
  return _mm256_add_epi64(x,
    _mm256_blend_epi32(
      _mm256_setzero_si256(), _mm256_permute4x64_epi64(x, _MM_SHUFFLE(1, 1, 0, 0)), 0xF0));
}

/// Of a and, with Both, of b, four at a time; the carried totals as in the 32-bit rows.
template <bool Both>
VAO_AVX2_INLINE void runningTotalsAvx2(std::int64_t* a, std::int64_t* b, std::int64_t n)
{
  __m256i carryA = _mm256_setzero_si256();
  __m256i carryB = _mm256_setzero_si256();
  std::int64_t i = 0;
  for (; i + 4 <= n; i += 4)
  {
    const __m256i x = scanLanes(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(a + i)));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(a + i), _mm256_add_epi64(x, carryA));
    carryA = _mm256_add_epi64(carryA, _mm256_permute4x64_epi64(x, _MM_SHUFFLE(3, 3, 3, 3)));
    if constexpr (Both)
    {
      const __m256i y = scanLanes(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(b + i)));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(b + i), _mm256_add_epi64(y, carryB));
      carryB = _mm256_add_epi64(carryB, _mm256_permute4x64_epi64(y, _MM_SHUFFLE(3, 3, 3, 3)));
    }
  }
  runningTotalsPlain(a, b, i, n);
}

/// 32-bit running totals eight at a time: within each 128-bit half by two shifted adds,
/// then the low half's total added to the high half. The carried total of the values
/// before is added last; its next value sums the scan's own last lane, so the chain from
/// one eight to the next is a single addition.
VAO_AVX2_INLINE void runningTotalsAvx2Row(std::uint32_t* a, std::int64_t n)
{
  const __m256i last = _mm256_set1_epi32(7);
  __m256i carry = _mm256_setzero_si256();
  std::int64_t i = 0;
  for (; i + 8 <= n; i += 8)
  {
    __m256i x = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(a + i));
    x = _mm256_add_epi32(x, _mm256_slli_si256(x, 4));
    x = _mm256_add_epi32(x, _mm256_slli_si256(x, 8));
    // Lane 3 of each half in every lane of it; the low half's moved up, zeros below.
    x = _mm256_add_epi32(x, _mm256_permute2x128_si256(_mm256_shuffle_epi32(x, 0xFF), x, 0x08));
    _mm256_storeu_si256(reinterpret_cast<__m256i*>(a + i), _mm256_add_epi32(x, carry));
    carry = _mm256_add_epi32(carry, _mm256_permutevar8x32_epi32(x, last));
  }
  runningTotalsOfRow(a, i, n);
}

/// Of a and, with Both, of b, one row after the other.
template <bool Both>
VAO_AVX2_INLINE void runningTotalsAvx2(std::uint32_t* a, std::uint32_t* b, std::int64_t n)
{
  runningTotalsAvx2Row(a, n);
  if constexpr (Both)
    runningTotalsAvx2Row(b, n);
}

/// The running totals within sixteen 32-bit lanes: lane k gains lanes k - 1, k - 2, k - 4,
/// k - 8 in turn.
VAO_AVX512_TARGET inline __m512i scanLanes32(__m512i x)
{
  const __m512i zero = _mm512_setzero_si512();
  x = _mm512_add_epi32(x, _mm512_alignr_epi32(x, zero, 15));
  x = _mm512_add_epi32(x, _mm512_alignr_epi32(x, zero, 14));
  x = _mm512_add_epi32(x, _mm512_alignr_epi32(x, zero, 12));
  return _mm512_add_epi32(x, _mm512_alignr_epi32(x, zero, 8));
}

/// The AVX-512 lanes of totals of V (32- or 64-bit): how many a vector holds, the scan
/// within it, the addition, and the last lane's total in every lane.
template <class V>
struct LanesOf
{
  static constexpr bool kNarrow = sizeof(V) == 4;
  static constexpr int kCount = kNarrow ? 16 : 8;
  static VAO_AVX512_TARGET __m512i scan(__m512i x)
  {
    return kNarrow ? scanLanes32(x) : scanLanes(x);
  }
  static VAO_AVX512_TARGET __m512i add(__m512i x, __m512i y)
  {
    return kNarrow ? _mm512_add_epi32(x, y) : _mm512_add_epi64(x, y);
  }
  static VAO_AVX512_TARGET __m512i last(__m512i x)
  {
    return kNarrow ? _mm512_permutexvar_epi32(_mm512_set1_epi32(kCount - 1), x)
                   : _mm512_permutexvar_epi64(_mm512_set1_epi64(kCount - 1), x);
  }
};

/// Running totals of a and, with Both, of b, a vector at a time: the scan within the vector
/// plus the total carried from the one before. The carried total's next value sums the
/// scan's own last lane, so the chain from one vector to the next is a single addition.
template <class L, bool Both, class V>
VAO_AVX512_TARGET void runningTotalsAvx512(V* a, V* b, std::int64_t n)
{
  __m512i carryA = _mm512_setzero_si512();
  __m512i carryB = _mm512_setzero_si512();
  std::int64_t i = 0;
  for (; i + L::kCount <= n; i += L::kCount)
  {
    const __m512i x = L::scan(_mm512_loadu_si512(a + i));
    _mm512_storeu_si512(a + i, L::add(x, carryA));
    carryA = L::add(carryA, L::last(x));
    if constexpr (Both)
    {
      const __m512i y = L::scan(_mm512_loadu_si512(b + i));
      _mm512_storeu_si512(b + i, L::add(y, carryB));
      carryB = L::add(carryB, L::last(y));
    }
  }
  runningTotalsPlain(a, b, i, n);
}

#endif

/// The widest tier the processor has, for 64- or 32-bit rows alike.
template <class V>
void runningTotalsOnTier(V* a, V* b, std::int64_t n, SimdTier tier)
{
#if VAO_HAVE_AVX2_TARGET
  if (tier >= SimdTier::Avx512)
  {
    if (b)
      runningTotalsAvx512<LanesOf<V>, true>(a, b, n);
    else
      runningTotalsAvx512<LanesOf<V>, false>(a, static_cast<V*>(nullptr), n);
    return;
  }
  if (tier == SimdTier::Avx2)
  {
    if (b)
      runningTotalsAvx2<true>(a, b, n);
    else
      runningTotalsAvx2<false>(a, nullptr, n);
    return;
  }
#endif
  (void)tier;
  runningTotalsPlain(a, b, 0, n);
}

} // namespace

void runningTotals(std::int64_t* a, std::int64_t* b, std::int64_t n, SimdTier tier)
{
  runningTotalsOnTier(a, b, n, tier);
}

void runningTotals(std::uint32_t* a, std::uint32_t* b, std::int64_t n, SimdTier tier)
{
  runningTotalsOnTier(a, b, n, tier);
}

} // namespace detail
} // namespace vao
