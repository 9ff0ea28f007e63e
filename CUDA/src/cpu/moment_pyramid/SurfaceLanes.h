// The surface queries' lanes (LevelGrid.h) in vector registers, and the dispatch between
// them and the plain loops: the Chebyshev sample and the shadow march of
// SurfaceLanes-inl.h, compiled for AVX2 + FMA (four lanes a vector) and AVX-512 (eight),
// both the same bits. (GCC does not vectorise the plain loops: their
// float-to-int conversions and selects stay branches.)
#pragma once

#include "cpu/moment_pyramid/LevelGrid.h"
#include "cpu/moment_pyramid/RawSampler.h"
#include "cpu/simd/EstimatorLanes.h"
#include "cpu/simd/GatherLanes.h"

#include <cmath>
#include <vector>

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

/// One step of the march: its distance from the start and its level.
struct MarchStep
{
  double t;
  int level;
};

/// Every march's steps: they depend on the distance alone, so every point takes the same.
/// The list ends at kMarchMaxSteps, or past `reach` (twice the box's diagonal: a march
/// that starts in the box has left it, so its lanes have stopped there). The distance is
/// counted in units of r_0, whose steps (halves of r_l / r_0 = 2^l) add exactly: summed in
/// world units, a step meant to land on a level's first distance (t = 3 r_0, 7 r_0, ...)
/// could round below it wherever r_0 is not a short binary fraction, and march on the
/// finer level, so that the shadows changed with the unit of the spacing.
inline std::vector<MarchStep> marchSchedule(const double* kernelRadius, int levels, double reach)
{
  std::vector<MarchStep> steps;
  for (double u = 0.0; steps.size() < static_cast<std::size_t>(kMarchMaxSteps);)
  {
    const double t = u * kernelRadius[0];
    if (t > reach)
      break;
    const int l = marchLevel(u, 1.0, levels);
    steps.push_back({ t, l });
    u += kMarchStepFraction * (kernelRadius[l] / kernelRadius[0]);
  }
  return steps;
}

#define VAO_TIER_FILE "cpu/moment_pyramid/SurfaceLanes-inl.h"
#include "cpu/simd/ForEachTier.h"

#if VAO_HAVE_AVX2_TARGET

/// The Chebyshev shadow march of a batch (SurfaceLanes-inl.h) in the widest tier the
/// processor has: `tier` is Avx2 or Avx512. `rays`: null, or the RayBounds (their data)
/// of the schedule's last level, `rayLevel`.
inline void chebyshevMarch(SimdTier tier, const LevelGrid* grids,
  const std::vector<MarchStep>& schedule, const double* lo, const double* hi,
  const double* const* start, const double* light, const double* query, double* occlusion,
  const float* rays = nullptr, int rayLevel = -1)
{
  const auto march = tier == SimdTier::Avx512 ? avx512::chebyshevMarch : avx2::chebyshevMarch;
  march(grids, schedule.data(), schedule.size(), lo, hi, start, light, query, occlusion, rays,
    rayLevel);
}
#endif

/// The occlusions of kLanes samples of one level with the given estimator: Chebyshev on
/// AVX2 or AVX-512 where the indices fit in 32 bits, else the plain loop (the exact erf
/// has no vector form here).
inline void occlusionLanes(const LevelGrid& g, Method estimator, const double* x, const double* y,
  const double* z, const double* query, double* occlusion)
{
#if VAO_HAVE_AVX2_TARGET
  const SimdTier tier = cpuSimdTier();
  if (estimator == Method::Chebyshev && tier >= SimdTier::Avx2 && g.narrowIndices)
  {
    if (tier == SimdTier::Avx512)
      avx512::chebyshevLanes(g, x, y, z, query, occlusion);
    else
      avx2::chebyshevLanes(g, x, y, z, query, occlusion);
    return;
  }
#endif
  occlusionLanesPlain(g, estimator, x, y, z, query, occlusion);
}

/// RawSampler's values at kLanes positions: rawLanes (SurfaceLanes-inl.h) on AVX2 or
/// AVX-512 where the volume's indices fit in 32 bits, else one position at a time.
template <class T>
void rawLanes(
  const RawSampler<T>& s, const double* x, const double* y, const double* z, double* out)
{
#if VAO_HAVE_AVX2_TARGET
  const SimdTier tier = cpuSimdTier();
  if (tier >= SimdTier::Avx2 && s.narrowIndices)
  {
    if (tier == SimdTier::Avx512)
      avx512::rawLanes(s, x, y, z, out);
    else
      avx2::rawLanes(s, x, y, z, out);
    return;
  }
#endif
  for (int k = 0; k < kLanes; ++k)
    out[k] = s({ x[k], y[k], z[k] });
}

/// trilinearSample's means at kLanes positions: meanLanes (SurfaceLanes-inl.h) where the
/// vector lanes apply.
inline void meanLanes(
  const LevelGrid& g, const double* x, const double* y, const double* z, double* mean)
{
#if VAO_HAVE_AVX2_TARGET
  const SimdTier tier = cpuSimdTier();
  if (tier >= SimdTier::Avx2 && g.narrowIndices)
  {
    if (tier == SimdTier::Avx512)
      avx512::meanLanes(g, x, y, z, mean);
    else
      avx2::meanLanes(g, x, y, z, mean);
    return;
  }
#endif
  for (int k = 0; k < kLanes; ++k)
  {
    double variance;
    trilinearSample(g, x[k], y[k], z[k], mean[k], variance);
  }
}

/// prefetchLanes (SurfaceLanes-inl.h) where the vector lanes apply.
inline void prefetchLanes(const LevelGrid& g, const double* x, const double* y, const double* z)
{
#if VAO_HAVE_AVX2_TARGET
  const SimdTier tier = cpuSimdTier();
  if (tier == SimdTier::Avx512 && g.narrowIndices)
    avx512::prefetchLanes(g, x, y, z);
  else if (tier == SimdTier::Avx2 && g.narrowIndices)
    avx2::prefetchLanes(g, x, y, z);
#endif
}

} // namespace detail
} // namespace vao
