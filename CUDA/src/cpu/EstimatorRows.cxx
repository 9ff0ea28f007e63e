// opennessRow: the Gaussian CDF, Chebyshev and CDF Reconstruction four voxels at a time on
// AVX2. The exact erf and pow are glibc's vector forms (libmvec, within 4 ulps of the
// scalar functions: the float32 openness is the scalar's but where the double lies within
// a few ulps of a float32 rounding boundary, or, for the erf, in the far tail where
// 1 + erf cancels).
// Everything else rounds as the scalar formulas (this file has no fused multiply-adds).
#include "EstimatorRows.h"

#include "EstimatorsAvx2.h"

#if VAO_HAVE_AVX2_TARGET && defined(VAO_HAVE_LIBMVEC)
#define VAO_VECTOR_MATH 1
// glibc's AVX2 erf and pow (their x86-64 vector function ABI names for 4 doubles).
extern "C" __attribute__((target("avx2"))) __m256d _ZGVdN4v_erf(__m256d);
extern "C" __attribute__((target("avx2"))) __m256d _ZGVdN4vv_pow(__m256d, __m256d);
#else
#define VAO_VECTOR_MATH 0
#endif

namespace vao
{
namespace detail
{

void opennessRowPlain(Method method, ErfMode erfMode, const NeighbourhoodRow& row, const double* query,
  double isoValue, float* openness, std::int64_t begin)
{
  for (std::int64_t i = begin; i < row.size; ++i)
  {
    const double q = query ? query[i] : isoValue;
    openness[i] = static_cast<float>(opennessFromStats(method, q, row.stats(i), erfMode));
  }
}

#if VAO_HAVE_AVX2_TARGET
namespace
{

#if VAO_VECTOR_MATH
/// opennessGaussianCdf with the exact erf. Flat lanes take a variance of 1 into the erf
/// (their 0 would give it infinities or NaN, and libmvec a slow path) and their flat
/// answer after it.
VAO_AVX2_HELPER __m256d gaussianCdfAvx2(
  __m256d q, __m256d mean, __m256d variance, __m256d roundingVariance, __m256d roundingSpread)
{
  const __m256d one = _mm256_set1_pd(1.0);
  const __m256d flat = flatMaskAvx2(mean, variance, roundingVariance);
  const __m256d spread = _mm256_blendv_pd(variance, one, flat);
  const __m256d z = _mm256_div_pd(_mm256_sub_pd(q, mean), _mm256_sqrt_pd(_mm256_mul_pd(_mm256_set1_pd(2.0), spread)));
  // Beyond |z| = 6 erf is +-1 in doubles (1 - erf(6) ~ 2e-17 is under half an ulp of 1), so
  // the openness is 1 or 0: groups of only such lanes and flat ones skip the erf (most of a
  // volume with smooth regions).
  const __m256d saturated = _mm256_cmp_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), z), _mm256_set1_pd(6.0), _CMP_GT_OQ);
  __m256d open;
  if (_mm256_movemask_pd(_mm256_or_pd(saturated, flat)) == 0xF)
  {
    open = _mm256_and_pd(_mm256_cmp_pd(z, _mm256_setzero_pd(), _CMP_GT_OQ), one);
  }
  else
  {
    const __m256d cdf = _mm256_mul_pd(_mm256_set1_pd(0.5), _mm256_add_pd(one, _ZGVdN4v_erf(z)));
    open = _mm256_min_pd(_mm256_max_pd(cdf, _mm256_setzero_pd()), one);
  }
  return _mm256_blendv_pd(open, flatOpennessAvx2(q, mean, roundingSpread), flat);
}

/// opennessCdfReconstruction: t^beta, its cases (flat box, t at or past either end, the
/// mean at the maximum) by masks in the scalar form's order of precedence. The lanes of
/// those cases take t = 1/2 and beta = 1 into the pow; groups of only such lanes skip it.
VAO_AVX2_HELPER __m256d cdfReconstructionAvx2(__m256d q, __m256d mean, __m256d minimum, __m256d maximum)
{
  const __m256d zero = _mm256_setzero_pd();
  const __m256d one = _mm256_set1_pd(1.0);
  const __m256d flat = _mm256_cmp_pd(maximum, minimum, _CMP_LE_OQ);
  const __m256d flatOpen = _mm256_and_pd(_mm256_cmp_pd(q, minimum, _CMP_GE_OQ), one);
  const __m256d range = _mm256_blendv_pd(_mm256_sub_pd(maximum, minimum), one, flat);
  const __m256d t = _mm256_div_pd(_mm256_sub_pd(q, minimum), range);
  const __m256d atTop = _mm256_cmp_pd(t, one, _CMP_GE_OQ);
  const __m256d atBottom = _mm256_cmp_pd(t, zero, _CMP_LE_OQ);
  const __m256d m = _mm256_min_pd(_mm256_max_pd(mean, minimum), maximum);
  const __m256d meanAtMaximum = _mm256_cmp_pd(m, maximum, _CMP_GE_OQ);
  const __m256d decided = _mm256_or_pd(_mm256_or_pd(flat, atTop), _mm256_or_pd(atBottom, meanAtMaximum));
  // Every decided lane but t >= 1 (and a flat box's, which comes last) is 0.
  __m256d open = _mm256_and_pd(atTop, one);
  if (_mm256_movemask_pd(decided) != 0xF)
  {
    const __m256d half = _mm256_set1_pd(0.5);
    const __m256d beta = _mm256_div_pd(_mm256_sub_pd(m, minimum), _mm256_blendv_pd(_mm256_sub_pd(maximum, m), one, decided));
    const __m256d power = _ZGVdN4vv_pow(_mm256_blendv_pd(t, half, decided), _mm256_blendv_pd(beta, one, decided));
    open = _mm256_blendv_pd(power, open, decided);
  }
  return _mm256_blendv_pd(open, flatOpen, flat);
}
#endif

/// Four opennesses at voxel i of the row by method M (opennessRowIsVector says which).
template <Method M>
VAO_AVX2_HELPER __m128 opennessFour(const NeighbourhoodRow& row, const double* query, double isoValue,
  std::int64_t i, __m256d roundingVariance, __m256d roundingSpread)
{
  const __m256d q = query ? _mm256_loadu_pd(query + i) : _mm256_set1_pd(isoValue);
  const __m256d mean = _mm256_loadu_pd(row.mean + i);
  if (M == Method::Chebyshev)
  {
    const __m256d variance = _mm256_loadu_pd(row.variance + i);
    return _mm256_cvtpd_ps(chebyshevOpennessAvx2(q, mean, variance, roundingVariance, roundingSpread));
  }
#if VAO_VECTOR_MATH
  if (M == Method::CdfReconstruction)
  {
    return _mm256_cvtpd_ps(
      cdfReconstructionAvx2(q, mean, _mm256_loadu_pd(row.minimum + i), _mm256_loadu_pd(row.maximum + i)));
  }
  const __m256d variance = _mm256_loadu_pd(row.variance + i);
  return _mm256_cvtpd_ps(gaussianCdfAvx2(q, mean, variance, roundingVariance, roundingSpread));
#else
  return _mm_setzero_ps(); // not reached: opennessRowIsVector says no
#endif
}

template <Method M>
VAO_AVX2_INLINE void opennessRowAvx2(const NeighbourhoodRow& row, const double* query, double isoValue,
  float* openness)
{
  const __m256d roundingVariance = _mm256_set1_pd(row.roundingVariance);
  const __m256d roundingSpread = _mm256_set1_pd(flatRoundingSpread(row.roundingVariance));
  std::int64_t i = 0;
  for (; i + 4 <= row.size; i += 4)
  {
    _mm_storeu_ps(openness + i, opennessFour<M>(row, query, isoValue, i, roundingVariance, roundingSpread));
  }
  opennessRowPlain(M, ErfMode::Exact, row, query, isoValue, openness, i);
}

} // namespace
#endif

bool opennessRowIsVector(Method method, ErfMode erfMode)
{
  const bool chebyshev = method == Method::Chebyshev;
  const bool gaussian = VAO_VECTOR_MATH && method == Method::GaussianCdf && erfMode == ErfMode::Exact;
  const bool reconstruction = VAO_VECTOR_MATH && method == Method::CdfReconstruction;
  return cpuHasAvx2() && (chebyshev || gaussian || reconstruction);
}

void opennessRow(Method method, ErfMode erfMode, const NeighbourhoodRow& row, const double* query,
  double isoValue, float* openness)
{
#if VAO_HAVE_AVX2_TARGET
  if (opennessRowIsVector(method, erfMode))
  {
    if (method == Method::Chebyshev)
      opennessRowAvx2<Method::Chebyshev>(row, query, isoValue, openness);
    else if (method == Method::CdfReconstruction)
      opennessRowAvx2<Method::CdfReconstruction>(row, query, isoValue, openness);
    else
      opennessRowAvx2<Method::GaussianCdf>(row, query, isoValue, openness);
    return;
  }
#endif
  opennessRowPlain(method, erfMode, row, query, isoValue, openness);
}

} // namespace detail
} // namespace vao
