#include "RunningTotals.h"

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
void runningTotalsPlain(std::int64_t* a, std::int64_t* b, std::int64_t begin, std::int64_t n)
{
  if (begin >= n)
    return;
  if (!b)
  {
    runningTotalsOfRow(a, begin, n);
    return;
  }
  std::int64_t totalA = begin > 0 ? a[begin - 1] : 0;
  std::int64_t totalB = begin > 0 ? b[begin - 1] : 0;
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

/// Of a and, with Both, of b.
template <bool Both>
VAO_AVX512_TARGET void runningTotalsAvx512(std::int64_t* a, std::int64_t* b, std::int64_t n)
{
  const __m512i last = _mm512_set1_epi64(7);
  __m512i carryA = _mm512_setzero_si512();
  __m512i carryB = _mm512_setzero_si512();
  std::int64_t i = 0;
  for (; i + 8 <= n; i += 8)
  {
    const __m512i x = _mm512_add_epi64(scanLanes(_mm512_loadu_si512(a + i)), carryA);
    _mm512_storeu_si512(a + i, x);
    carryA = _mm512_permutexvar_epi64(last, x);
    if constexpr (Both)
    {
      const __m512i y = _mm512_add_epi64(scanLanes(_mm512_loadu_si512(b + i)), carryB);
      _mm512_storeu_si512(b + i, y);
      carryB = _mm512_permutexvar_epi64(last, y);
    }
  }
  runningTotalsPlain(a, b, i, n);
}
#endif

} // namespace

void runningTotals(std::int64_t* a, std::int64_t* b, std::int64_t n, SimdTier tier)
{
#if VAO_HAVE_AVX2_TARGET
  if (tier >= SimdTier::Avx512)
  {
    if (b)
      runningTotalsAvx512<true>(a, b, n);
    else
      runningTotalsAvx512<false>(a, nullptr, n);
    return;
  }
#endif
  (void)tier;
  runningTotalsPlain(a, b, 0, n);
}

void runningTotals(std::uint32_t* a, std::int64_t n)
{
  runningTotalsOfRow(a, 0, n);
}

} // namespace detail
} // namespace vao
