// The estimators of Estimators.h on four doubles at a time (AVX2), for the volume's rows
// (EstimatorRows.cxx) and the surface lanes (SurfaceLanes.h). Both branches of a formula
// are formed and one is kept by a mask. Files that include this are compiled without
// fused multiply-adds (-ffp-contract=off), so each lane rounds as the scalar formula does.
#pragma once

#include "CpuDispatch.h"

#include "vao/Estimators.h"

#if VAO_HAVE_AVX2_TARGET
#include <immintrin.h>

namespace vao
{
namespace detail
{

/// isFlatVariance: all bits set in the lanes whose box is flat.
VAO_AVX2_HELPER __m256d flatMaskAvx2(__m256d mean, __m256d variance, __m256d roundingVariance)
{
  const __m256d scale = _mm256_max_pd(_mm256_mul_pd(mean, mean), _mm256_set1_pd(1.0));
  const __m256d limit = _mm256_max_pd(roundingVariance, _mm256_mul_pd(_mm256_set1_pd(kFlatEpsilon), scale));
  return _mm256_cmp_pd(variance, limit, _CMP_LE_OQ);
}

/// flatOpennessWithin: 1 where q >= mean - max(roundingSpread, kFlatSpread max(1, |mean|)).
VAO_AVX2_HELPER __m256d flatOpennessAvx2(__m256d q, __m256d mean, __m256d roundingSpread)
{
  const __m256d one = _mm256_set1_pd(1.0);
  const __m256d magnitude = _mm256_max_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), mean), one);
  const __m256d spread = _mm256_max_pd(roundingSpread, _mm256_mul_pd(_mm256_set1_pd(kFlatSpread), magnitude));
  return _mm256_and_pd(_mm256_cmp_pd(q, _mm256_sub_pd(mean, spread), _CMP_GE_OQ), one);
}

/// opennessChebyshevWithin (the bound's 0/0 on a flat box is not kept).
VAO_AVX2_HELPER __m256d chebyshevOpennessAvx2(
  __m256d q, __m256d mean, __m256d variance, __m256d roundingVariance, __m256d roundingSpread)
{
  const __m256d zero = _mm256_setzero_pd();
  const __m256d one = _mm256_set1_pd(1.0);
  const __m256d d = _mm256_sub_pd(q, mean);
  const __m256d share = _mm256_div_pd(variance, _mm256_add_pd(variance, _mm256_mul_pd(d, d)));
  const __m256d bound = _mm256_and_pd(_mm256_cmp_pd(d, zero, _CMP_GT_OQ),
    _mm256_min_pd(_mm256_max_pd(_mm256_sub_pd(one, share), zero), one));
  return _mm256_blendv_pd(
    bound, flatOpennessAvx2(q, mean, roundingSpread), flatMaskAvx2(mean, variance, roundingVariance));
}

} // namespace detail
} // namespace vao
#endif
