// opennessRow: the Gaussian CDF and Chebyshev four voxels at a time on AVX2. The exact erf
// is glibc's vector erf (libmvec, within 4 ulps of the scalar erf: the float32 openness is
// the scalar's but where the double lies within a few ulps of a float32 rounding boundary).
// Everything else rounds as the scalar formulas (this file has no fused multiply-adds).
#include "EstimatorRows.h"

#include "EstimatorsAvx2.h"

#if VAO_HAVE_AVX2_TARGET && defined(VAO_HAVE_LIBMVEC)
#define VAO_VECTOR_ERF 1
// glibc's AVX2 erf (the x86-64 vector function ABI name of erf for 4 doubles).
extern "C" __attribute__((target("avx2"))) __m256d _ZGVdN4v_erf(__m256d);
#else
#define VAO_VECTOR_ERF 0
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

/// Four opennesses at voxel i of the row: Method::GaussianCdf (exact erf) or Chebyshev.
template <Method M>
VAO_AVX2_HELPER __m128 opennessFour(const NeighbourhoodRow& row, const double* query, double isoValue,
  std::int64_t i, __m256d roundingVariance, __m256d roundingSpread)
{
  const __m256d q = query ? _mm256_loadu_pd(query + i) : _mm256_set1_pd(isoValue);
  const __m256d mean = _mm256_loadu_pd(row.mean + i);
  const __m256d variance = _mm256_loadu_pd(row.variance + i);
  if (M == Method::Chebyshev)
  {
    return _mm256_cvtpd_ps(chebyshevOpennessAvx2(q, mean, variance, roundingVariance, roundingSpread));
  }
#if VAO_VECTOR_ERF
  // opennessGaussianCdf. Flat lanes take a variance of 1 into the erf (their 0 would give
  // it infinities or NaN, and libmvec a slow path) and their flat answer after it.
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
  return _mm256_cvtpd_ps(_mm256_blendv_pd(open, flatOpennessAvx2(q, mean, roundingSpread), flat));
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
  const bool gaussian = VAO_VECTOR_ERF && method == Method::GaussianCdf && erfMode == ErfMode::Exact;
  return cpuHasAvx2() && (chebyshev || gaussian);
}

void opennessRow(Method method, ErfMode erfMode, const NeighbourhoodRow& row, const double* query,
  double isoValue, float* openness)
{
#if VAO_HAVE_AVX2_TARGET
  if (opennessRowIsVector(method, erfMode))
  {
    if (method == Method::Chebyshev)
      opennessRowAvx2<Method::Chebyshev>(row, query, isoValue, openness);
    else
      opennessRowAvx2<Method::GaussianCdf>(row, query, isoValue, openness);
    return;
  }
#endif
  opennessRowPlain(method, erfMode, row, query, isoValue, openness);
}

} // namespace detail
} // namespace vao
