// The surface queries' lanes (LevelGrid.h) on AVX2 + FMA, and the dispatch between them
// and the plain loops: the trilinear Chebyshev sample of four lanes per vector by 32-bit
// gathers, and the whole shadow march of a batch in vector registers, so one step is
// few enough instructions for the processor to overlap the gathers' latency of several.
// (GCC does not vectorise the plain loops: their float-to-int conversions and selects stay
// branches.) Equal to the plain loops but for the rounding of the blends' fused
// multiply-adds; the vector march also passes over the samples that their cell's bound
// (CellBounds) shows cannot raise a lane's occlusion, which changes no maximum.
#pragma once

#include "EstimatorLanes.h"
#include "LevelGrid.h"

#include <cmath>

namespace vao
{
namespace detail
{

/// The shadow march's rules, shared by its plain and vector forms: steps of half the
/// level's radius (a blob of the level's size cannot fall between two), a stop at this
/// occlusion, and the level at distance t: clamp(floor(log2(1 + t / r0)), 0, levels - 1).
constexpr double kMarchStepFraction = 0.5;
constexpr int kMarchMaxSteps = 1 << 16;
constexpr double kMarchFullOcclusion = 0.999;
inline int marchLevel(double t, double r0, int levels)
{
  return std::min(levels - 1, std::max(0, static_cast<int>(std::floor(std::log2(1.0 + t / r0)))));
}

#if VAO_HAVE_AVX2_TARGET
VAO_AVX2_HELPER __m256d lerpAvx2(__m256d a, __m256d b, __m256d t)
{
  return _mm256_fmadd_pd(t, _mm256_sub_pd(b, a), a);
}

/// Four trilinear blends of c: cells from `base` (32-bit indices), corner steps per axis
/// (0 where clamped), fractions f (trilinearSample's nested lerps).
VAO_AVX2_HELPER __m256d blendAvx2(const float* c, __m128i base, const __m128i* step, const __m256d* f)
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

/// blendAvx2 where every cell's x corners are adjacent (the lower one at most dims - 2,
/// the fraction 1 at the last voxel): each row's two corners are one 64-bit gather.
VAO_AVX2_HELPER __m256d blendPairsAvx2(const float* c, __m128i base, const __m128i* step, const __m256d* f)
{
  const __m128i corner[4] = { base, _mm_add_epi32(base, step[1]), _mm_add_epi32(base, step[2]),
    _mm_add_epi32(_mm_add_epi32(base, step[2]), step[1]) };
  const __m256i split = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
  __m256d rows[4];
  for (int r = 0; r < 4; ++r)
  {
    // Four (lower, upper) float pairs, regrouped as four lowers then four uppers.
    const __m256i pairs = _mm256_i32gather_epi64(reinterpret_cast<const long long*>(c), corner[r], 4);
    const __m256 grouped = _mm256_permutevar8x32_ps(_mm256_castsi256_ps(pairs), split);
    rows[r] = lerpAvx2(_mm256_cvtps_pd(_mm256_castps256_ps128(grouped)),
      _mm256_cvtps_pd(_mm256_extractf128_ps(grouped, 1)), f[0]);
  }
  return lerpAvx2(lerpAvx2(rows[0], rows[1], f[1]), lerpAvx2(rows[2], rows[3], f[1]), f[2]);
}

/// blendAvx2 of the means and the variances of a tiled level (LevelGrid::tiled), whose
/// (mean, variance) pairs are one 64-bit gather per corner.
VAO_AVX2_HELPER void blendTiledAvx2(const float* c, __m128i base, const __m128i* step, const __m256d* f,
  __m256d& mean, __m256d& variance)
{
  const __m128i corner[4] = { base, _mm_add_epi32(base, step[1]), _mm_add_epi32(base, step[2]),
    _mm_add_epi32(_mm_add_epi32(base, step[2]), step[1]) };
  const __m256i split = _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7);
  __m256d means[4], variances[4];
  for (int r = 0; r < 4; ++r)
  {
    __m256d m[2], v[2];
    for (int side = 0; side < 2; ++side)
    {
      const __m128i at = side ? _mm_add_epi32(corner[r], step[0]) : corner[r];
      const __m256i pairs = _mm256_i32gather_epi64(reinterpret_cast<const long long*>(c), at, 4);
      const __m256 grouped = _mm256_permutevar8x32_ps(_mm256_castsi256_ps(pairs), split);
      m[side] = _mm256_cvtps_pd(_mm256_castps256_ps128(grouped));
      v[side] = _mm256_cvtps_pd(_mm256_extractf128_ps(grouped, 1));
    }
    means[r] = lerpAvx2(m[0], m[1], f[0]);
    variances[r] = lerpAvx2(v[0], v[1], f[0]);
  }
  mean = lerpAvx2(lerpAvx2(means[0], means[1], f[1]), lerpAvx2(means[2], means[3], f[1]), f[2]);
  variance = lerpAvx2(lerpAvx2(variances[0], variances[1], f[1]), lerpAvx2(variances[2], variances[3], f[1]), f[2]);
}

/// Four lanes' cells of one level: the lower corners per axis and as flat 32-bit indices,
/// the steps to the upper corners (0 where clamped) and the fractions towards them.
struct CellsAvx2
{
  __m128i lower[3];
  __m128i base;
  __m128i step[3];
  __m256d f[3];
};

VAO_AVX2_HELPER CellsAvx2 cellsAvx2(const LevelGrid& g, const __m256d* position)
{
  const __m256d zero = _mm256_setzero_pd();
  CellsAvx2 c;
  c.base = _mm_setzero_si128();
  __m128i tile = _mm_setzero_si128();
  for (int a = 0; a < 3; ++a)
  {
    const __m256d maxIndex = _mm256_set1_pd(g.maxIndex[a]);
    const __m256d offset = _mm256_sub_pd(position[a], _mm256_set1_pd(g.origin[a]));
    const __m256d u = _mm256_min_pd(
      _mm256_max_pd(_mm256_mul_pd(offset, _mm256_set1_pd(g.inverseSpacing[a])), zero), maxIndex);
    __m128i lower = _mm256_cvttpd_epi32(u);
    if (a == 0 && g.pairedRows) // the last voxel as the upper corner of the cell below it
      lower = _mm_min_epi32(lower, _mm_set1_epi32(static_cast<int>(g.maxIndex[0]) - 1));
    c.lower[a] = lower;
    c.f[a] = _mm256_sub_pd(u, _mm256_cvtepi32_pd(lower));
    const __m128i stride = _mm_set1_epi32(static_cast<int>(g.stride[a]));
    if (g.tiled) // trilinearSample's tiled index: the tile, and the corner within it
    {
      const __m128i tileStride = _mm_set1_epi32(static_cast<int>(g.tileStride[a]));
      tile = _mm_add_epi32(tile, _mm_mullo_epi32(_mm_srli_epi32(lower, 3), tileStride));
      c.base = _mm_add_epi32(c.base, _mm_mullo_epi32(_mm_and_si128(lower, _mm_set1_epi32(7)), stride));
    }
    else
      c.base = _mm_add_epi32(c.base, _mm_mullo_epi32(lower, stride));
    // The 64-bit lane masks of u < maxIndex, narrowed to 32 bits.
    const __m256i below = _mm256_castpd_si256(_mm256_cmp_pd(u, maxIndex, _CMP_LT_OQ));
    const __m128i narrow =
      _mm256_castsi256_si128(_mm256_permutevar8x32_epi32(below, _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7)));
    c.step[a] = _mm_and_si128(narrow, stride);
  }
  if (g.tiled)
    c.base = _mm_add_epi32(c.base, _mm_i32gather_epi32(g.tileOffsets, tile, 4));
  return c;
}

/// The Chebyshev occlusion of q in four cells (occlusionLanesPlain's formula): the corners
/// by 32-bit gathers, the blends and both of the estimator's branches in vector
/// arithmetic, one kept by a mask.
VAO_AVX2_HELPER __m256d chebyshevCellsAvx2(const LevelGrid& g, const CellsAvx2& c, __m256d q)
{
  __m256d mean, variance;
  if (g.tiled)
  {
    blendTiledAvx2(g.mean, c.base, c.step, c.f, mean, variance);
  }
  else
  {
    mean = g.pairedRows ? blendPairsAvx2(g.mean, c.base, c.step, c.f) : blendAvx2(g.mean, c.base, c.step, c.f);
    variance = g.pairedRows ? blendPairsAvx2(g.variance, c.base, c.step, c.f) : blendAvx2(g.variance, c.base, c.step, c.f);
  }
  variance = _mm256_max_pd(variance, _mm256_setzero_pd());
  return _mm256_sub_pd(_mm256_set1_pd(1.0), avx2::chebyshevOpenness(q, mean, variance,
    _mm256_set1_pd(g.roundingVariance), _mm256_set1_pd(g.roundingSpread)));
}

/// The Chebyshev occlusion of q at four world positions of one level.
VAO_AVX2_HELPER __m256d chebyshevOcclusionAvx2(const LevelGrid& g, const __m256d* position, __m256d q)
{
  return chebyshevCellsAvx2(g, cellsAvx2(g, position), q);
}

/// Upper bounds of the Chebyshev occlusion of q in four cells, from the level's
/// CellBounds: 1 where q is not above the cell's largest mean or the bound is NaN.
VAO_AVX2_HELPER __m256d chebyshevBoundAvx2(const LevelGrid& g, const CellsAvx2& c, __m256d q)
{
  const __m256d one = _mm256_set1_pd(1.0);
  const __m256i pairs = _mm256_i32gather_epi64(reinterpret_cast<const long long*>(g.cellBounds), c.base, 8);
  const __m256 grouped =
    _mm256_permutevar8x32_ps(_mm256_castsi256_ps(pairs), _mm256_setr_epi32(0, 2, 4, 6, 1, 3, 5, 7));
  const __m256d mean = _mm256_cvtps_pd(_mm256_castps256_ps128(grouped));
  const __m256d variance = _mm256_cvtps_pd(_mm256_extractf128_ps(grouped, 1));
  const __m256d d = _mm256_sub_pd(q, mean);
  const __m256d share = _mm256_div_pd(variance, _mm256_add_pd(variance, _mm256_mul_pd(d, d)));
  const __m256d defined = _mm256_and_pd(_mm256_cmp_pd(d, _mm256_setzero_pd(), _CMP_GT_OQ),
    _mm256_cmp_pd(share, share, _CMP_ORD_Q));
  return _mm256_blendv_pd(one, share, defined);
}

/// occlusionLanesPlain for Chebyshev, four lanes per vector.
VAO_AVX2_INLINE void chebyshevLanesAvx2(const LevelGrid& g, const double* x, const double* y, const double* z,
  const double* query, double* occlusion)
{
  for (int h = 0; h < kLanes; h += 4)
  {
    const __m256d position[3] = { _mm256_loadu_pd(x + h), _mm256_loadu_pd(y + h), _mm256_loadu_pd(z + h) };
    _mm256_storeu_pd(occlusion + h, chebyshevOcclusionAvx2(g, position, _mm256_loadu_pd(query + h)));
  }
}

/// The Chebyshev shadow march of a batch (batchMarch in SurfaceSampling.cxx, whose rules it
/// follows lane by lane) with the positions, bounds, occlusions and the lanes still
/// marching in registers: from start (x, y, z per lane) along the unit light, inside
/// [lo, hi], on levels whose indices fit in 32 bits.
VAO_AVX2_INLINE void chebyshevMarchAvx2(const LevelGrid* grids, const double* kernelRadius, int levels,
  const double* lo, const double* hi, const double* const* start, const double* light, const double* query,
  double* occlusion)
{
  constexpr int kHalves = kLanes / 4;
  const __m256d full = _mm256_set1_pd(kMarchFullOcclusion);
  __m256d occ[kHalves], alive[kHalves], q[kHalves], from[kHalves][3];
  for (int h = 0; h < kHalves; ++h)
  {
    occ[h] = _mm256_setzero_pd();
    alive[h] = _mm256_castsi256_pd(_mm256_set1_epi64x(-1));
    q[h] = _mm256_loadu_pd(query + 4 * h);
    for (int a = 0; a < 3; ++a)
      from[h][a] = _mm256_loadu_pd(start[a] + 4 * h);
  }
  const double r0 = kernelRadius[0];
  double t = 0.0;
  for (int s = 0; s < kMarchMaxSteps; ++s)
  {
    __m256d at[kHalves][3];
    int any = 0;
    for (int h = 0; h < kHalves; ++h)
    {
      for (int a = 0; a < 3; ++a)
      {
        // start + t * light rounded as the plain loop does (no fused multiply-add): both
        // forms stop at the same step on a bound.
        at[h][a] = _mm256_add_pd(from[h][a], _mm256_mul_pd(_mm256_set1_pd(t), _mm256_set1_pd(light[a])));
        const __m256d inside = _mm256_and_pd(_mm256_cmp_pd(at[h][a], _mm256_set1_pd(lo[a]), _CMP_GE_OQ),
          _mm256_cmp_pd(at[h][a], _mm256_set1_pd(hi[a]), _CMP_LE_OQ));
        alive[h] = _mm256_and_pd(alive[h], inside);
      }
      any |= _mm256_movemask_pd(alive[h]);
    }
    if (!any)
      break;
    const int l = marchLevel(t, r0, levels);
    const LevelGrid& grid = grids[l];
    for (int h = 0; h < kHalves; ++h)
    {
      const CellsAvx2 cells = cellsAvx2(grid, at[h]);
      if (grid.cellBounds)
      {
        // No lane still marching can rise above its occlusion here: the sample is passed
        // over, as the maximum it would enter is already held.
        const __m256d bound = chebyshevBoundAvx2(grid, cells, q[h]);
        const __m256d mayRaise = _mm256_andnot_pd(_mm256_cmp_pd(bound, occ[h], _CMP_LE_OQ), alive[h]);
        if (_mm256_testz_pd(mayRaise, mayRaise))
          continue;
      }
      const __m256d sample = chebyshevCellsAvx2(grid, cells, q[h]);
      occ[h] = _mm256_blendv_pd(occ[h], _mm256_max_pd(sample, occ[h]), alive[h]);
      alive[h] = _mm256_and_pd(alive[h], _mm256_cmp_pd(occ[h], full, _CMP_LT_OQ));
    }
    t += kMarchStepFraction * kernelRadius[l];
  }
  for (int h = 0; h < kHalves; ++h)
    _mm256_storeu_pd(occlusion + 4 * h, occ[h]);
}
#endif

/// The occlusions of kLanes samples of one level with the given estimator: Chebyshev on
/// AVX2 where the indices fit in 32 bits, else the plain loop (the exact erf has no vector
/// form here).
inline void occlusionLanes(const LevelGrid& g, Method estimator, const double* x, const double* y, const double* z,
  const double* query, double* occlusion)
{
#if VAO_HAVE_AVX2_TARGET
  if (estimator == Method::Chebyshev && cpuHasAvx2() && g.narrowIndices)
  {
    chebyshevLanesAvx2(g, x, y, z, query, occlusion);
    return;
  }
#endif
  occlusionLanesPlain(g, estimator, x, y, z, query, occlusion);
}

} // namespace detail
} // namespace vao
