// meanVarianceRowExact. The vector form computes count * sumSquares - sum^2 in doubles,
// which is exact while both products stay below 2^52 (as they do for 16-bit CT values in
// boxes of thousands of voxels); lanes that could leave that range take the integer
// formula. Either way the result is meanVarianceFromExactSums's, bit for bit (this file
// has no fused multiply-adds, though here they could not change an exact product).
#include "MomentRows.h"

#include "CpuDispatch.h"

#include "vao/Estimators.h"

#if VAO_HAVE_AVX2_TARGET
#include <immintrin.h>
#endif

namespace vao
{
namespace detail
{

void meanVarianceRowExactPlain(const std::int64_t* sum, const std::int64_t* sumSquares, const std::int64_t* countX,
  std::int64_t countYZ, std::int64_t n, double* count, double* mean, double* variance, std::int64_t begin)
{
  for (std::int64_t i = begin; i < n; ++i)
  {
    const std::int64_t c = countX[i] * countYZ;
    count[i] = static_cast<double>(c);
    meanVarianceFromExactSums(sum[i], sumSquares[i], c, mean[i], variance[i]);
  }
}

#if VAO_HAVE_AVX2_TARGET
namespace
{

/// Integers of magnitude below 2^51 to doubles (exact): added to the bits of 1.5 * 2^52,
/// they are its mantissa.
VAO_AVX2_HELPER __m256d smallIntegersToDouble(__m256i x)
{
  const __m256d magic = _mm256_set1_pd(6755399441055744.0);
  return _mm256_sub_pd(_mm256_castsi256_pd(_mm256_add_epi64(x, _mm256_castpd_si256(magic))), magic);
}

VAO_AVX2_INLINE void meanVarianceRowExactAvx2(const std::int64_t* sum,
  const std::int64_t* sumSquares, const std::int64_t* countX, std::int64_t countYZ, std::int64_t n, double* count,
  double* mean, double* variance)
{
  const __m256i limit = _mm256_set1_epi64x(std::int64_t(1) << 50);
  const __m256i negativeLimit = _mm256_set1_epi64x(-(std::int64_t(1) << 50));
  const __m256d exact = _mm256_set1_pd(4503599627370496.0); // 2^52
  const __m256d yz = _mm256_set1_pd(static_cast<double>(countYZ));
  const __m256d zero = _mm256_setzero_pd();
  for (std::int64_t i = 0; i + 4 <= n; i += 4)
  {
    const __m256i s = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(sum + i));
    const __m256i s2 = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(sumSquares + i));
    const __m256i inRange = _mm256_and_si256(_mm256_and_si256(_mm256_cmpgt_epi64(limit, s),
      _mm256_cmpgt_epi64(s, negativeLimit)), _mm256_cmpgt_epi64(limit, s2));
    if (_mm256_movemask_pd(_mm256_castsi256_pd(inRange)) == 0xF)
    {
      const __m256d c = _mm256_mul_pd(
        smallIntegersToDouble(_mm256_loadu_si256(reinterpret_cast<const __m256i*>(countX + i))), yz);
      const __m256d sd = smallIntegersToDouble(s);
      const __m256d a = _mm256_mul_pd(c, smallIntegersToDouble(s2));
      const __m256d b = _mm256_mul_pd(sd, sd);
      const __m256d big = _mm256_or_pd(_mm256_cmp_pd(a, exact, _CMP_GE_OQ), _mm256_cmp_pd(b, exact, _CMP_GE_OQ));
      if (_mm256_movemask_pd(big) == 0)
      {
        const __m256d numerator = _mm256_sub_pd(a, b);
        const __m256d v = _mm256_div_pd(numerator, _mm256_mul_pd(c, c));
        _mm256_storeu_pd(count + i, c);
        _mm256_storeu_pd(mean + i, _mm256_div_pd(sd, c));
        _mm256_storeu_pd(variance + i, _mm256_and_pd(_mm256_cmp_pd(numerator, zero, _CMP_GT_OQ), v));
        continue;
      }
    }
    meanVarianceRowExactPlain(sum, sumSquares, countX, countYZ, i + 4, count, mean, variance, i);
  }
  meanVarianceRowExactPlain(sum, sumSquares, countX, countYZ, n, count, mean, variance, n - n % 4);
}

} // namespace
#endif

void meanVarianceRowExact(const std::int64_t* sum, const std::int64_t* sumSquares, const std::int64_t* countX,
  std::int64_t countYZ, std::int64_t n, double* count, double* mean, double* variance)
{
#if VAO_HAVE_AVX2_TARGET
  if (cpuHasAvx2())
  {
    meanVarianceRowExactAvx2(sum, sumSquares, countX, countYZ, n, count, mean, variance);
    return;
  }
#endif
  meanVarianceRowExactPlain(sum, sumSquares, countX, countYZ, n, count, mean, variance);
}

} // namespace detail
} // namespace vao
