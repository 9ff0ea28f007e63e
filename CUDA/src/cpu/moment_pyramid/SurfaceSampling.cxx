// Surface ambient occlusion and soft shadows sampled from the moment pyramid (Penner &
// Mitchell 2008; docs/methods.md, Penner and Mitchell).
#include "vao/Validation.h"
#include "vao/VarianceOcclusionMap.h"

#include "VolumeAccess.h"
#include "cpu/common/Parallel.h"
#include "cpu/moment_pyramid/LevelTiles.h"
#include "cpu/moment_pyramid/PreparedPyramid.h"
#include "cpu/moment_pyramid/SurfaceBatches.h"
#include "cpu/moment_pyramid/SurfaceChecks.h"
#include "cpu/moment_pyramid/SurfaceLanes.h"
#include "cpu/moment_pyramid/SurfaceWalk.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace vao
{
namespace
{

using detail::MarchBounds;
using detail::PointLanes;
using detail::RawSampler;

using detail::PreparedPyramid;

} // namespace

double sampleVolume(const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const std::array<double, 3>& position)
{
  return detail::dispatchScalarType(volume.type,
    [&](auto tag)
    {
      using T = decltype(tag);
      return RawSampler<T>(detail::TypedVolume<T>(volume), origin, spacing)(position);
    });
}

void sampleLevel(
  const MomentLevel& level, const std::array<double, 3>& position, double& mean, double& variance)
{
  detail::trilinearSample(
    detail::LevelGrid(level), position[0], position[1], position[2], mean, variance);
}

namespace
{

/// The occlusions of a batch of surface points from the levels used (sampled at
/// p + k r_l n, combined by maximum or mean).
template <class Query>
void batchOcclusion(const PreparedPyramid& pyramid, int levels, PointLanes& lanes,
  const SurfaceOcclusionParameters& parameters, const Query& query, double* combined)
{
  constexpr int W = detail::kLanes;
  double x[2][W], y[2][W], z[2][W], occlusion[W];
  std::fill(combined, combined + W, 0.0);
  // Level l's sample positions, in slot l % 2.
  const auto positions = [&](int l)
  { lanes.along(parameters.offsetFactor * pyramid.kernelRadius[l], x[l % 2], y[l % 2], z[l % 2]); };
  // Levels 0 and 1 (96% of a pyramid's bytes) are far larger than the caches: the batch
  // first asks for their lines, so their misses overlap instead of following one another.
  for (int l = 0; l < std::min(levels, 2); ++l)
  {
    positions(l);
    detail::prefetchLanes(pyramid.grids[l], x[l], y[l], z[l]);
  }
  query(lanes); // after the requests: its own misses (the raw volume's) overlap theirs
  for (int l = 0; l < levels; ++l)
  {
    if (l >= 2)
      positions(l);
    const int slot = l % 2;
    detail::occlusionLanes(
      pyramid.grids[l], parameters.estimator, x[slot], y[slot], z[slot], lanes.query, occlusion);
    for (int k = 0; k < W; ++k)
    {
      combined[k] = parameters.combination == LevelCombination::Mean
        ? combined[k] + occlusion[k] / levels
        : std::max(combined[k], occlusion[k]);
    }
  }
}

/// The largest occlusion each lane's march meets from p + r_0 n along the unit `light`.
/// The lanes share the steps (t and the level depend on the distance alone); a lane stops
/// on leaving the bounds or at full occlusion, the batch when every lane has.
void batchMarch(const PreparedPyramid& pyramid, const MarchBounds& bounds,
  const std::vector<detail::MarchStep>& schedule, const PointLanes& lanes,
  const std::array<double, 3>& light, Method estimator, double* occlusion)
{
  constexpr int W = detail::kLanes;
  const double r0 = pyramid.kernelRadius[0];
  double sx[W], sy[W], sz[W], x[W], y[W], z[W], sample[W];
  for (int k = 0; k < W; ++k)
  {
    const std::array<double, 3> start = lanes.along(k, r0);
    sx[k] = start[0];
    sy[k] = start[1];
    sz[k] = start[2];
  }
#if VAO_HAVE_AVX2_TARGET
  if (estimator == Method::Chebyshev && pyramid.vectorMarch)
  {
    const double* start[3] = { sx, sy, sz };
    detail::chebyshevMarch(pyramid.tier, pyramid.grids.data(), schedule, bounds.lo, bounds.hi,
      start, light.data(), lanes.query, occlusion, pyramid.rayBounds(), pyramid.rayLevel());
    return;
  }
#endif
  bool alive[W];
  std::fill(occlusion, occlusion + W, 0.0);
  std::fill(alive, alive + W, true);
  for (const detail::MarchStep& step : schedule)
  {
    const double t = step.t;
    bool any = false;
    for (int k = 0; k < W; ++k)
    {
      x[k] = sx[k] + t * light[0];
      y[k] = sy[k] + t * light[1];
      z[k] = sz[k] + t * light[2];
      const double at[3] = { x[k], y[k], z[k] };
      alive[k] = alive[k] && bounds.contains(at);
      any = any || alive[k];
    }
    if (!any)
    {
      break;
    }
    detail::occlusionLanes(pyramid.grids[step.level], estimator, x, y, z, lanes.query, sample);
    for (int k = 0; k < W; ++k)
    {
      if (alive[k])
      {
        occlusion[k] = std::max(occlusion[k], sample[k]);
        alive[k] = occlusion[k] < detail::kMarchFullOcclusion;
      }
    }
  }
}

/// A surface query in two parts for the sweep (SurfaceWalk.h): mark(lanes, tiles) marks
/// the tiled levels' tiles a batch's samples reach, sample(lanes) writes its results.
/// withOcclusion and withShadow check their arguments, prepare the levels and return
/// run(mark, sample), or the error. `tiles`: a SurfacePyramid's tiled levels, or null.
template <class P, class Run>
Status withOcclusion(const std::vector<MomentLevel>& pyramid, PyramidTiles* tiles,
  const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const P* points, const P* normals, std::int64_t count,
  const SurfaceOcclusionParameters& parameters, float* out, Run&& run)
{
  int levels = 0;
  Status status = detail::checkQuery(
    pyramid, parameters, points, normals, count, out, levels, tiles ? tiles->count() : 0);
  const bool half = parameters.query == SurfaceQuery::HalfVoxelInside;
  if (status.ok && half)
  {
    status = checkVolume(volume);
    if (status.ok)
      status = checkSpacing(spacing, "the volume's spacing");
    if (status.ok)
      status = checkFinitePoint(origin, "the volume's origin");
    if (!status.ok)
      status.message = "the half-voxel-inside query needs the volume: " + status.message;
  }
  if (!status.ok)
  {
    return status;
  }
  const double h = std::min(spacing[0], std::min(spacing[1], spacing[2]));
  // The tiled levels' samples: at p + k r_l n (batchOcclusion's positions).
  const auto mark = [&](const PointLanes& lanes, PyramidTiles& t)
  {
    for (int l = 0; l < std::min(levels, t.count()); ++l)
    {
      const double offset = parameters.offsetFactor * pyramid[l].kernelRadius;
      for (int k = 0; k < lanes.used; ++k)
      {
        const std::array<double, 3> at = lanes.along(k, offset);
        t.at(l)->markAround(at[0], at[1], at[2]);
      }
    }
  };
  const PreparedPyramid prepared(pyramid, levels, tiles);
  return detail::dispatchScalarType(half ? volume.type : ScalarType::Float32,
    [&](auto tag)
    {
      const RawSampler<decltype(tag)> raw(
        detail::TypedVolume<decltype(tag)>(half ? volume : VolumeView{}),
        half ? origin : std::array<double, 3>{ 0, 0, 0 },
        half ? spacing : std::array<double, 3>{ 1, 1, 1 });
      const auto query = [&](PointLanes& lanes)
      {
        if (half)
        {
          double x[detail::kLanes], y[detail::kLanes], z[detail::kLanes];
          lanes.along(-0.5 * h, x, y, z);
          detail::rawLanes(raw, x, y, z, lanes.query);
        }
        else
          std::fill(lanes.query, lanes.query + detail::kLanes, parameters.isoValue);
      };
      const auto sample = [&](PointLanes& lanes)
      {
        double occlusion[detail::kLanes];
        batchOcclusion(prepared, levels, lanes, parameters, query, occlusion);
        for (int k = 0; k < lanes.used; ++k)
        {
          out[lanes.index[k]] = static_cast<float>(1.0 - clamp01(occlusion[k]));
        }
      };
      return run(mark, sample);
    });
}

template <class P, class Run>
Status withShadow(const std::vector<MomentLevel>& pyramid, PyramidTiles* tiles, const P* points,
  const P* normals, std::int64_t count, const std::array<double, 3>& lightDirection,
  const SurfaceOcclusionParameters& parameters, float* out, Run&& run)
{
  int levels = 0;
  Status status = detail::checkQuery(
    pyramid, parameters, points, normals, count, out, levels, tiles ? tiles->count() : 0);
  if (status.ok)
    status = checkFinitePoint(lightDirection, "the light direction");
  if (!status.ok)
  {
    return status;
  }
  const double lightLength = std::sqrt(lightDirection[0] * lightDirection[0] +
    lightDirection[1] * lightDirection[1] + lightDirection[2] * lightDirection[2]);
  if (!(lightLength > 0.0))
  {
    return Status::failure("the light direction must not be zero");
  }
  const std::array<double, 3> light = { lightDirection[0] / lightLength,
    lightDirection[1] / lightLength, lightDirection[2] / lightLength };
  const MomentLevel& base = pyramid[0];
  const double h = std::min(base.spacing[0], std::min(base.spacing[1], base.spacing[2]));
  const MarchBounds bounds(base);
  // The tiled levels' samples: the query half a voxel inside (level 0) and the march's
  // steps while it is on them (batchMarch's positions, whatever the occlusion met).
  const double r0 = base.kernelRadius;
  PreparedPyramid prepared(pyramid, levels, tiles);
  const std::vector<detail::MarchStep> schedule =
    detail::marchSchedule(prepared.kernelRadius.data(), levels, 2.0 * bounds.diagonal());
  const auto mark = [&](const PointLanes& lanes, PyramidTiles& t)
  {
    for (int k = 0; k < lanes.used; ++k)
    {
      const std::array<double, 3> inside = lanes.along(k, -0.5 * h);
      const std::array<double, 3> start = lanes.along(k, r0);
      t.at(0)->markAround(inside[0], inside[1], inside[2]);
      for (const detail::MarchStep& step : schedule)
      {
        const double s = step.t;
        const double at[3] = { start[0] + s * light[0], start[1] + s * light[1],
          start[2] + s * light[2] };
        if (!t.at(step.level) || !bounds.contains(at))
          break;
        t.at(step.level)->markAround(at[0], at[1], at[2]);
      }
    }
  };
  prepared.boundCells(count);
  prepared.boundRays(light);
  const auto sample = [&](PointLanes& lanes)
  {
    if (parameters.query == SurfaceQuery::HalfVoxelInside)
    {
      // No raw volume here: level 0's (blurred) mean half a voxel inside.
      double x[detail::kLanes], y[detail::kLanes], z[detail::kLanes];
      lanes.along(-0.5 * h, x, y, z);
      detail::meanLanes(prepared.grids[0], x, y, z, lanes.query);
    }
    else
      std::fill(lanes.query, lanes.query + detail::kLanes, parameters.isoValue);
    double occlusion[detail::kLanes];
    batchMarch(prepared, bounds, schedule, lanes, light, parameters.estimator, occlusion);
    for (int k = 0; k < lanes.used; ++k)
    {
      out[lanes.index[k]] = static_cast<float>(1.0 - clamp01(occlusion[k]));
    }
  };
  return run(mark, sample);
}

/// run(mark, sample) of withOcclusion or withShadow: the sweep of the points.
template <class P>
auto sweepWith(PyramidTiles* tiles, const P* points, const P* normals, std::int64_t count,
  const Execution& execution)
{
  return [=, &execution](auto& mark, auto& sample)
  {
    return detail::sweepPoints(tiles, points, normals, count, execution, mark, sample)
      ? Status::success()
      : Status::cancelled();
  };
}

/// Every query's entry: its buffers (cell and ray bounds, sweep order) and, on a
/// SurfacePyramid, the tiles it builds may run out of memory, which becomes a Status.
const char* const kQueryBuffers = "the surface query's buffers (tiles, cell and ray bounds)";

template <class P>
Status guardedOcclusion(const std::vector<MomentLevel>& levels, PyramidTiles* tiles,
  const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const P* points, const P* normals, std::int64_t count,
  const SurfaceOcclusionParameters& parameters, float* out, const Execution& execution)
{
  return catchOutOfMemory(kQueryBuffers,
    [&]
    {
      return withOcclusion(levels, tiles, volume, origin, spacing, points, normals, count,
        parameters, out, sweepWith(tiles, points, normals, count, execution));
    });
}

template <class P>
Status guardedShadow(const std::vector<MomentLevel>& levels, PyramidTiles* tiles, const P* points,
  const P* normals, std::int64_t count, const std::array<double, 3>& lightDirection,
  const SurfaceOcclusionParameters& parameters, float* out, const Execution& execution)
{
  return catchOutOfMemory(kQueryBuffers,
    [&]
    {
      return withShadow(levels, tiles, points, normals, count, lightDirection, parameters, out,
        sweepWith(tiles, points, normals, count, execution));
    });
}

/// Both queries in one sweep: each batch marks the tiles of both and samples both, so a
/// tile both reach is built once (their results are those of the two sweeps).
template <class P>
Status guardedBoth(const std::vector<MomentLevel>& levels, PyramidTiles* tiles,
  const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const P* points, const P* normals, std::int64_t count,
  const std::array<double, 3>& lightDirection, const SurfaceOcclusionParameters& parameters,
  float* occlusion, float* shadow, const Execution& execution)
{
  const auto sweep = sweepWith(tiles, points, normals, count, execution);
  return catchOutOfMemory(kQueryBuffers,
    [&]
    {
      return withOcclusion(levels, tiles, volume, origin, spacing, points, normals, count,
        parameters, occlusion,
        [&](auto& markOcclusion, auto& sampleOcclusion)
        {
          return withShadow(levels, tiles, points, normals, count, lightDirection, parameters,
            shadow,
            [&](auto& markShadow, auto& sampleShadow)
            {
              const auto mark = [&](const PointLanes& lanes, PyramidTiles& t)
              {
                markOcclusion(lanes, t);
                markShadow(lanes, t);
              };
              const auto sample = [&](PointLanes& lanes)
              {
                sampleOcclusion(lanes);
                sampleShadow(lanes);
              };
              return sweep(mark, sample);
            });
        });
    });
}

} // namespace

Status surfaceAmbientOcclusion(const std::vector<MomentLevel>& pyramid, const VolumeView& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing, const double* points,
  const double* normals, std::int64_t count, const SurfaceOcclusionParameters& parameters,
  float* out, const Execution& execution)
{
  return guardedOcclusion(
    pyramid, nullptr, volume, origin, spacing, points, normals, count, parameters, out, execution);
}

Status surfaceAmbientOcclusion(const std::vector<MomentLevel>& pyramid, const VolumeView& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing, const float* points,
  const float* normals, std::int64_t count, const SurfaceOcclusionParameters& parameters,
  float* out, const Execution& execution)
{
  return guardedOcclusion(
    pyramid, nullptr, volume, origin, spacing, points, normals, count, parameters, out, execution);
}

Status surfaceShadow(const std::vector<MomentLevel>& pyramid, const double* points,
  const double* normals, std::int64_t count, const std::array<double, 3>& lightDirection,
  const SurfaceOcclusionParameters& parameters, float* out, const Execution& execution)
{
  return guardedShadow(
    pyramid, nullptr, points, normals, count, lightDirection, parameters, out, execution);
}

Status surfaceShadow(const std::vector<MomentLevel>& pyramid, const float* points,
  const float* normals, std::int64_t count, const std::array<double, 3>& lightDirection,
  const SurfaceOcclusionParameters& parameters, float* out, const Execution& execution)
{
  return guardedShadow(
    pyramid, nullptr, points, normals, count, lightDirection, parameters, out, execution);
}

Status surfaceAmbientOcclusion(SurfacePyramid& pyramid, const VolumeView& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing, const double* points,
  const double* normals, std::int64_t count, const SurfaceOcclusionParameters& parameters,
  float* out, const Execution& execution)
{
  return guardedOcclusion(pyramid.levels(), SurfacePyramidAccess::tiles(pyramid).get(), volume,
    origin, spacing, points, normals, count, parameters, out, execution);
}

Status surfaceAmbientOcclusion(SurfacePyramid& pyramid, const VolumeView& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing, const float* points,
  const float* normals, std::int64_t count, const SurfaceOcclusionParameters& parameters,
  float* out, const Execution& execution)
{
  return guardedOcclusion(pyramid.levels(), SurfacePyramidAccess::tiles(pyramid).get(), volume,
    origin, spacing, points, normals, count, parameters, out, execution);
}

Status surfaceShadow(SurfacePyramid& pyramid, const double* points, const double* normals,
  std::int64_t count, const std::array<double, 3>& lightDirection,
  const SurfaceOcclusionParameters& parameters, float* out, const Execution& execution)
{
  return guardedShadow(pyramid.levels(), SurfacePyramidAccess::tiles(pyramid).get(), points,
    normals, count, lightDirection, parameters, out, execution);
}

Status surfaceShadow(SurfacePyramid& pyramid, const float* points, const float* normals,
  std::int64_t count, const std::array<double, 3>& lightDirection,
  const SurfaceOcclusionParameters& parameters, float* out, const Execution& execution)
{
  return guardedShadow(pyramid.levels(), SurfacePyramidAccess::tiles(pyramid).get(), points,
    normals, count, lightDirection, parameters, out, execution);
}

Status surfaceOcclusionAndShadow(SurfacePyramid& pyramid, const VolumeView& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing, const double* points,
  const double* normals, std::int64_t count, const std::array<double, 3>& lightDirection,
  const SurfaceOcclusionParameters& parameters, float* occlusion, float* shadow,
  const Execution& execution)
{
  return guardedBoth(pyramid.levels(), SurfacePyramidAccess::tiles(pyramid).get(), volume, origin,
    spacing, points, normals, count, lightDirection, parameters, occlusion, shadow, execution);
}

Status surfaceOcclusionAndShadow(SurfacePyramid& pyramid, const VolumeView& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing, const float* points,
  const float* normals, std::int64_t count, const std::array<double, 3>& lightDirection,
  const SurfaceOcclusionParameters& parameters, float* occlusion, float* shadow,
  const Execution& execution)
{
  return guardedBoth(pyramid.levels(), SurfacePyramidAccess::tiles(pyramid).get(), volume, origin,
    spacing, points, normals, count, lightDirection, parameters, occlusion, shadow, execution);
}

} // namespace vao
