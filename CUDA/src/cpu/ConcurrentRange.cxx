#include "ConcurrentRange.h"

#include "CpuDispatch.h"

#include <cmath>

#if VAO_HAVE_AVX2_TARGET
#include <immintrin.h>
#endif

namespace vao
{
namespace detail
{

namespace
{

bool rowExtremesPlain(const float* v, std::int64_t n, float& lo, float& hi)
{
  bool finite = true;
  for (std::int64_t i = 0; i < n; ++i)
  {
    lo = v[i] < lo ? v[i] : lo;
    hi = v[i] > hi ? v[i] : hi;
    finite = finite && std::isfinite(v[i]);
  }
  return finite;
}

#if VAO_HAVE_AVX2_TARGET
VAO_AVX512_TARGET bool rowExtremesAvx512(const float* v, std::int64_t n, float& lo, float& hi)
{
  const __m512 zero = _mm512_setzero_ps();
  __m512 low = _mm512_set1_ps(lo), high = _mm512_set1_ps(hi);
  __mmask16 infinite = 0; // x * 0 is not 0 at a NaN or an infinity
  std::int64_t i = 0;
  for (; i + 16 <= n; i += 16)
  {
    const __m512 x = _mm512_loadu_ps(v + i);
    low = _mm512_min_ps(low, x);
    high = _mm512_max_ps(high, x);
    infinite = static_cast<__mmask16>(infinite | _mm512_cmp_ps_mask(_mm512_mul_ps(x, zero), zero, _CMP_NEQ_UQ));
  }
  lo = _mm512_reduce_min_ps(low);
  hi = _mm512_reduce_max_ps(high);
  return rowExtremesPlain(v + i, n - i, lo, hi) && infinite == 0;
}
#endif

} // namespace

bool rowExtremes(const float* v, std::int64_t n, float& lo, float& hi)
{
#if VAO_HAVE_AVX2_TARGET
  if (cpuSimdTier() >= SimdTier::Avx512)
    return rowExtremesAvx512(v, n, lo, hi);
#endif
  return rowExtremesPlain(v, n, lo, hi);
}

} // namespace detail
} // namespace vao
