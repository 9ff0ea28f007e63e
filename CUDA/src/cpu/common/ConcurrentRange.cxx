#include "cpu/common/ConcurrentRange.h"

#include "cpu/simd/CpuDispatch.h"

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
__attribute__((target("avx2,fma"))) bool rowExtremesAvx2(
  const float* v, std::int64_t n, float& lo, float& hi)
{
  const __m256 zero = _mm256_setzero_ps();
  __m256 low = _mm256_set1_ps(lo), high = _mm256_set1_ps(hi);
  __m256 infinite = zero; // all bits set in a lane that met a NaN or an infinity (x * 0 not 0)
  std::int64_t i = 0;
  for (; i + 8 <= n; i += 8)
  {
    const __m256 x = _mm256_loadu_ps(v + i);
    low = _mm256_min_ps(low, x);
    high = _mm256_max_ps(high, x);
    infinite = _mm256_or_ps(infinite, _mm256_cmp_ps(_mm256_mul_ps(x, zero), zero, _CMP_NEQ_UQ));
  }
  // The eight lanes folded in halves: extremes are exact in any order.
  __m128 l = _mm_min_ps(_mm256_castps256_ps128(low), _mm256_extractf128_ps(low, 1));
  __m128 h = _mm_max_ps(_mm256_castps256_ps128(high), _mm256_extractf128_ps(high, 1));
  l = _mm_min_ps(l, _mm_movehl_ps(l, l));
  h = _mm_max_ps(h, _mm_movehl_ps(h, h));
  lo = _mm_cvtss_f32(_mm_min_ss(l, _mm_shuffle_ps(l, l, 1)));
  hi = _mm_cvtss_f32(_mm_max_ss(h, _mm_shuffle_ps(h, h, 1)));
  return rowExtremesPlain(v + i, n - i, lo, hi) && _mm256_movemask_ps(infinite) == 0;
}

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
    infinite = static_cast<__mmask16>(
      infinite | _mm512_cmp_ps_mask(_mm512_mul_ps(x, zero), zero, _CMP_NEQ_UQ));
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
  if (cpuHasAvx2())
    return rowExtremesAvx2(v, n, lo, hi);
#endif
  return rowExtremesPlain(v, n, lo, hi);
}

} // namespace detail
} // namespace vao
