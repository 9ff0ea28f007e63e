// Exact Rays: every voxel casts rayCount rays of length R through the volume and averages
// their transmittance. The cost is O(n R / h) per voxel: the reference the fast Rays
// method is measured against, as Exact Box is for the CDF methods.
//
// The rays run in world space: a direction w of the Fibonacci sphere moves the index
// coordinates by diag(1/h) D^T w per world unit (D the direction matrix, h the spacing),
// so anisotropic voxels and rotated images see the same directions a renderer does.
#include "cpu/ray_casting/ExactRays.h"

#include "VolumeAccess.h"
#include "cpu/common/ConcurrentRange.h"
#include "cpu/common/Parallel.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>

namespace vao
{

std::array<int, 3> rayReach(const RayParameters& rays)
{
  std::array<int, 3> reach{};
  for (int a = 0; a < 3; ++a)
  {
    const double voxels = rays.radius / rays.spacing[a];
    // Bounded so that an absurd radius cannot overflow; the callers' checks report it.
    reach[a] = std::isfinite(voxels) ? static_cast<int>(std::min(std::ceil(voxels), 1e9)) : 0;
  }
  return reach;
}

namespace detail
{

std::vector<std::array<double, 3>> fibonacciDirections(int n)
{
  const double pi = 3.14159265358979323846;
  const double turn = pi * (3.0 - std::sqrt(5.0)); // the golden angle
  std::vector<std::array<double, 3>> directions(static_cast<std::size_t>(std::max(n, 0)));
  for (int i = 0; i < n; ++i)
  {
    const double z = 1.0 - (2.0 * i + 1.0) / n;
    const double r = std::sqrt(std::max(0.0, 1.0 - z * z));
    const double phi = (i + 0.5) * turn;
    directions[static_cast<std::size_t>(i)] = { r * std::cos(phi), r * std::sin(phi), z };
  }
  return directions;
}

namespace
{

/// sigma at index coordinates q of the block: the value interpolated trilinearly, then
/// classified; -1 outside the block (where sigma is 0).
template <class T, class Extinction>
double extinctionAt(const TypedVolume<T>& volume, const double q[3], const Extinction& extinction)
{
  std::int64_t i0[3];
  double f[3];
  std::int64_t step[3];
  for (int a = 0; a < 3; ++a)
  {
    const std::int64_t n = volume.dims[a];
    if (!(q[a] >= 0.0 && q[a] <= static_cast<double>(n - 1)))
      return -1.0;
    // The last cell's far corner belongs to it, so that f stays in [0, 1].
    i0[a] = std::min(static_cast<std::int64_t>(q[a]), std::max<std::int64_t>(n - 2, 0));
    f[a] = q[a] - static_cast<double>(i0[a]);
    step[a] = n > 1 ? 1 : 0;
  }
  auto at = [&](std::int64_t dx, std::int64_t dy, std::int64_t dz)
  {
    return static_cast<double>(
      volume.value(i0[0] + dx * step[0], i0[1] + dy * step[1], i0[2] + dz * step[2]));
  };
  const double c00 = at(0, 0, 0) + f[0] * (at(1, 0, 0) - at(0, 0, 0));
  const double c10 = at(0, 1, 0) + f[0] * (at(1, 1, 0) - at(0, 1, 0));
  const double c01 = at(0, 0, 1) + f[0] * (at(1, 0, 1) - at(0, 0, 1));
  const double c11 = at(0, 1, 1) + f[0] * (at(1, 1, 1) - at(0, 1, 1));
  const double c0 = c00 + f[1] * (c10 - c00);
  const double c1 = c01 + f[1] * (c11 - c01);
  return extinction(c0 + f[2] * (c1 - c0));
}

template <class T>
bool castRays(const VolumeView& view, const Region& region,
  const AmbientOcclusionParameters& parameters, float* openness, ConcurrentRange* seen,
  const Execution& execution)
{
  const TypedVolume<T> volume(view);
  const RayParameters& rays = parameters.rays;
  const double smallest = std::min({ rays.spacing[0], rays.spacing[1], rays.spacing[2] });
  const double unit = rays.opacityUnitDistance > 0.0 ? rays.opacityUnitDistance : smallest;
  const auto steps = static_cast<std::int64_t>(std::ceil(rays.radius / (smallest / 2.0)));
  const double dt = rays.radius / static_cast<double>(steps);
  // Each direction's move in index coordinates per step dt: diag(1/h) D^T w dt.
  const std::vector<std::array<double, 3>> directions = fibonacciDirections(rays.rayCount);
  std::vector<std::array<double, 3>> moves(directions.size());
  for (std::size_t i = 0; i < directions.size(); ++i)
    for (int a = 0; a < 3; ++a)
    {
      const std::array<double, 9>& d = rays.direction;
      const std::array<double, 3>& w = directions[i];
      moves[i][a] = dt * (d[a] * w[0] + d[3 + a] * w[1] + d[6 + a] * w[2]) / rays.spacing[a];
    }
  const OpacityFunction& function = parameters.opacity;
  const auto extinction = [&function, unit](double v)
  { return -std::log1p(-std::min(evaluateOpacity(function, v), 1.0 - 1e-6)) / unit; };
  const std::int64_t nx = region.size[0];
  const std::int64_t rows = region.size[1] * region.size[2];
  const int threads = resolveThreadCount(execution.threads);
  const int chunks = static_cast<int>(std::min<std::int64_t>(rows, 64 * std::int64_t(threads)));
  return parallelFor(rows, chunks, threads, execution,
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress)
    {
      for (std::int64_t row = begin; row < end; ++row)
      {
        const std::int64_t y = region.begin[1] + row % region.size[1];
        const std::int64_t z = region.begin[2] + row / region.size[1];
        float* out = openness + row * nx;
        for (std::int64_t i = 0; i < nx; ++i)
        {
          const double origin[3] = { static_cast<double>(region.begin[0] + i),
            static_cast<double>(y), static_cast<double>(z) };
          double transmitted = 0.0;
          for (const std::array<double, 3>& move : moves)
          {
            double depth = 0.0;
            for (std::int64_t k = 0; k < steps; ++k)
            {
              const double t = static_cast<double>(k) + 0.5;
              const double q[3] = { origin[0] + t * move[0], origin[1] + t * move[1],
                origin[2] + t * move[2] };
              const double sigma = extinctionAt(volume, q, extinction);
              // The block is convex and the ray starts inside it: once out, out for good.
              if (sigma < 0.0)
                break;
              depth += sigma;
            }
            transmitted += std::exp(-dt * depth);
          }
          out[i] = static_cast<float>(transmitted / static_cast<double>(moves.size()));
        }
        if (seen)
          seen->add(out, nx);
        if (!progress.advance())
          return;
      }
    });
}

} // namespace

Status computeExactRays(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, float* openness, OutputRange* range,
  const Execution& execution)
{
  return keepingOutputRange(volume.type, range,
    [&](auto tag, ConcurrentRange* seen)
    { return castRays<decltype(tag)>(volume, region, parameters, openness, seen, execution); });
}

} // namespace detail
} // namespace vao
