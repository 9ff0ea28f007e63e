// A level of the moment pyramid prepared for many trilinear samples. The surface queries
// sample every point's levels tens of times (the shadow march), so the divisions, bounds
// and strides are done once here, and kLanes points are sampled together: their loads are
// independent (the processor overlaps the cache misses), and on AVX2 the lane loop
// compiles to gathers and vector arithmetic (CpuDispatch.h).
#pragma once

#include "CpuDispatch.h"
#include "vao/Estimators.h"
#include "vao/VarianceOcclusionMap.h"

#include <algorithm>
#include <cstdint>
#include <limits>

#if VAO_HAVE_AVX2_TARGET
#include <immintrin.h>
#endif

namespace vao
{
namespace detail
{

/// Points a surface query samples together.
constexpr int kLanes = 8;

/// The numbers of one level that its samples read.
struct LevelGrid
{
  const float* mean = nullptr;
  const float* variance = nullptr;
  double origin[3] = { 0, 0, 0 };
  double inverseSpacing[3] = { 1, 1, 1 };
  double maxIndex[3] = { 0, 0, 0 };     // dims - 1
  std::int64_t stride[3] = { 1, 0, 0 }; // 1, nx, nx ny
  double roundingVariance = 0.0;        // of the level's moments (the estimators' flat rule)
  double roundingSpread = 0.0;          // flatRoundingSpread(roundingVariance)
  // Voxel indices fit in 32 bits: the lanes use 32-bit gathers (else 64-bit ones).
  bool narrowIndices = true;

  LevelGrid() = default;
  explicit LevelGrid(const MomentLevel& level)
    : mean(level.mean.data())
    , variance(level.variance.data())
    , roundingVariance(level.roundingVariance)
    , roundingSpread(flatRoundingSpread(level.roundingVariance))
  {
    for (int a = 0; a < 3; ++a)
    {
      this->origin[a] = level.origin[a];
      this->inverseSpacing[a] = 1.0 / level.spacing[a];
      this->maxIndex[a] = static_cast<double>(level.dims[a] - 1);
    }
    this->stride[1] = level.dims[0];
    this->stride[2] = level.dims[0] * level.dims[1];
    this->narrowIndices = this->stride[2] * level.dims[2] <= std::numeric_limits<std::int32_t>::max();
  }
};

/// Trilinear mean and variance (clamped at 0) of the level at world (x, y, z), clamped to
/// the level's bounds: the cell's lower corner, the fractions towards the upper one, and
/// nested lerps along x, y, z. IndexT holds voxel indices (int32 where they fit).
template <class IndexT>
VAO_ALWAYS_INLINE void trilinearSample(const LevelGrid& g, double x, double y, double z, double& mean, double& variance)
{
  const double p[3] = { x, y, z };
  IndexT base = 0;
  IndexT step[3];
  double f[3];
  for (int a = 0; a < 3; ++a)
  {
    const double u = std::min(std::max((p[a] - g.origin[a]) * g.inverseSpacing[a], 0.0), g.maxIndex[a]);
    const IndexT lower = static_cast<IndexT>(u); // u >= 0: truncation is the floor
    f[a] = u - static_cast<double>(lower);
    base += lower * static_cast<IndexT>(g.stride[a]);
    step[a] = u < g.maxIndex[a] ? static_cast<IndexT>(g.stride[a]) : IndexT(0); // upper corner, clamped
  }
  auto blend = [&](const float* c) {
    auto lerp = [](double a, double b, double t) { return a + t * (b - a); };
    auto row = [&](IndexT i) { return lerp(c[i], c[i + step[0]], f[0]); };
    const double lowerPlane = lerp(row(base), row(base + step[1]), f[1]);
    const double upperPlane = lerp(row(base + step[2]), row(base + step[2] + step[1]), f[1]);
    return lerp(lowerPlane, upperPlane, f[2]);
  };
  mean = blend(g.mean);
  variance = std::max(0.0, blend(g.variance));
}

/// 1 - the estimator's openness of q for a level sample (the estimators of METHODS.md).
VAO_ALWAYS_INLINE double sampleOcclusion(Method estimator, double query, double mean, double variance,
  double roundingVariance)
{
  const NeighbourhoodStats stats{ mean, variance, mean, mean, roundingVariance };
  return 1.0 -
    (estimator == Method::GaussianCdf ? opennessGaussianCdf(query, stats, ErfMode::Exact)
                                      : opennessChebyshev(query, stats));
}

/// occlusion[k] = the Chebyshev occlusion of query[k] at world (x[k], y[k], z[k]) of one
/// level, for the kLanes lanes: the definition, and the path without AVX2.
template <class IndexT>
void chebyshevLanes(const LevelGrid& g, const double* x, const double* y, const double* z, const double* query,
  double* occlusion)
{
  for (int k = 0; k < kLanes; ++k)
  {
    double mean, variance;
    trilinearSample<IndexT>(g, x[k], y[k], z[k], mean, variance);
    occlusion[k] = 1.0 - opennessChebyshevWithin(query[k], mean, variance, g.roundingVariance, g.roundingSpread);
  }
}

#if VAO_HAVE_AVX2_TARGET
#define VAO_AVX2_INLINE __attribute__((target("avx2,fma"))) inline

VAO_AVX2_INLINE __m256d lerpAvx2(__m256d a, __m256d b, __m256d t)
{
  return _mm256_fmadd_pd(t, _mm256_sub_pd(b, a), a);
}

/// Four trilinear blends of c: cells from `base` (32-bit indices), corner steps per axis
/// (0 where clamped), fractions f (trilinearSample's nested lerps).
VAO_AVX2_INLINE __m256d blendAvx2(const float* c, __m128i base, const __m128i* step, const __m256d* f)
{
  const __m128i corner[4] = { base, _mm_add_epi32(base, step[1]), _mm_add_epi32(base, step[2]),
    _mm_add_epi32(_mm_add_epi32(base, step[2]), step[1]) };
  __m256d rows[4];
  for (int r = 0; r < 4; ++r)
  {
    const __m256d lo = _mm256_cvtps_pd(_mm_i32gather_ps(c, corner[r], 4));
    const __m256d hi = _mm256_cvtps_pd(_mm_i32gather_ps(c, _mm_add_epi32(corner[r], step[0]), 4));
    rows[r] = lerpAvx2(lo, hi, f[0]);
  }
  return lerpAvx2(lerpAvx2(rows[0], rows[1], f[1]), lerpAvx2(rows[2], rows[3], f[1]), f[2]);
}

/// chebyshevLanes<std::int32_t> four lanes per vector: the corners by 32-bit gathers, the
/// blends and the estimator's both branches in vector arithmetic, one kept by a mask.
/// (GCC does not vectorise the plain loop: its float-to-int conversions and selects stay
/// branches.) Equal to the plain loop but for the rounding of fused multiply-adds.
VAO_AVX2_INLINE void chebyshevLanesAvx2(const LevelGrid& g, const double* x,
  const double* y, const double* z, const double* query, double* occlusion)
{
  const double* position[3] = { x, y, z };
  const __m256d zero = _mm256_setzero_pd();
  const __m256d one = _mm256_set1_pd(1.0);
  for (int h = 0; h < kLanes; h += 4)
  {
    __m128i base = _mm_setzero_si128();
    __m128i step[3];
    __m256d f[3];
    for (int a = 0; a < 3; ++a)
    {
      const __m256d maxIndex = _mm256_set1_pd(g.maxIndex[a]);
      const __m256d offset = _mm256_sub_pd(_mm256_loadu_pd(position[a] + h), _mm256_set1_pd(g.origin[a]));
      const __m256d u = _mm256_min_pd(
        _mm256_max_pd(_mm256_mul_pd(offset, _mm256_set1_pd(g.inverseSpacing[a])), zero), maxIndex);
      const __m128i lower = _mm256_cvttpd_epi32(u);
      f[a] = _mm256_sub_pd(u, _mm256_cvtepi32_pd(lower));
      const __m128i stride = _mm_set1_epi32(static_cast<int>(g.stride[a]));
      base = _mm_add_epi32(base, _mm_mullo_epi32(lower, stride));
      // The 64-bit lane masks of u < maxIndex, narrowed to 32 bits.
      const __m256i below = _mm256_castpd_si256(_mm256_cmp_pd(u, maxIndex, _CMP_LT_OQ));
      const __m128i narrow =
        _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(below, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7)));
      step[a] = _mm_and_si128(narrow, stride);
    }
    const __m256d mean = blendAvx2(g.mean, base, step, f);
    const __m256d variance = _mm256_max_pd(blendAvx2(g.variance, base, step, f), zero);
    const __m256d q = _mm256_loadu_pd(query + h);
    // opennessChebyshevWithin, both branches.
    const __m256d d = _mm256_sub_pd(q, mean);
    const __m256d share = _mm256_div_pd(variance, _mm256_fmadd_pd(d, d, variance));
    const __m256d bound = _mm256_and_pd(_mm256_cmp_pd(d, zero, _CMP_GT_OQ),
      _mm256_min_pd(_mm256_max_pd(_mm256_sub_pd(one, share), zero), one));
    const __m256d flatLimit = _mm256_max_pd(_mm256_set1_pd(g.roundingVariance),
      _mm256_mul_pd(_mm256_set1_pd(kFlatEpsilon), _mm256_max_pd(_mm256_mul_pd(mean, mean), one)));
    const __m256d flat = _mm256_cmp_pd(variance, flatLimit, _CMP_LE_OQ);
    const __m256d magnitude = _mm256_max_pd(_mm256_andnot_pd(_mm256_set1_pd(-0.0), mean), one);
    const __m256d spread = _mm256_max_pd(_mm256_set1_pd(g.roundingSpread), _mm256_mul_pd(_mm256_set1_pd(kFlatSpread), magnitude));
    const __m256d flatOpen = _mm256_and_pd(_mm256_cmp_pd(q, _mm256_sub_pd(mean, spread), _CMP_GE_OQ), one);
    _mm256_storeu_pd(occlusion + h, _mm256_sub_pd(one, _mm256_blendv_pd(bound, flatOpen, flat)));
  }
}
#endif

/// The occlusions of kLanes samples of one level with the given estimator.
inline void occlusionLanes(const LevelGrid& g, Method estimator, const double* x, const double* y, const double* z,
  const double* query, double* occlusion)
{
  if (estimator == Method::Chebyshev)
  {
#if VAO_HAVE_AVX2_TARGET
    static const bool avx2 = cpuHasAvx2();
    if (avx2 && g.narrowIndices)
    {
      chebyshevLanesAvx2(g, x, y, z, query, occlusion);
      return;
    }
#endif
    if (g.narrowIndices)
      chebyshevLanes<std::int32_t>(g, x, y, z, query, occlusion);
    else
      chebyshevLanes<std::int64_t>(g, x, y, z, query, occlusion);
    return;
  }
  for (int k = 0; k < kLanes; ++k) // the exact erf has no vector form here
  {
    double mean, variance;
    trilinearSample<std::int64_t>(g, x[k], y[k], z[k], mean, variance);
    occlusion[k] = sampleOcclusion(estimator, query[k], mean, variance, g.roundingVariance);
  }
}

} // namespace detail
} // namespace vao
