// The Transfer Function method: O_tf(x) = 1 - (1/N) sum over the clipped box of alpha(v).
//
// Two passes. The first writes every voxel's opacity in fixed point, round(alpha * 2^24),
// as a float (integers up to 2^24 are exact in float), from a table of every value for 8-
// and 16-bit data and from evaluateOpacity for the rest. The second streams the box sums
// of that field (MomentPlanes.h, sums of v only): double sums of integers below 2^53 are
// exact, so the sums do not depend on threads or on how a distributed run cut the volume,
// and O_tf = (N 2^24 - S) / (N 2^24) rounds once. The fixed point costs at most 2^-25 per
// voxel (3e-8, within the 1e-6 the method promises), and a 0/1 opacity (a step at c) is
// exact: the result is then Exact Box's with the iso value c, bit for bit.
#include "cpu/transfer_function/TransferFunctionOpenness.h"

#include "cpu/box_statistics/MomentPlanes.h"
#include "cpu/common/Parallel.h"
#include "vao/Storage.h"

#include <atomic>
#include <cmath>
#include <limits>
#include <type_traits>
#include <vector>

namespace vao
{
namespace detail
{

namespace
{

/// The fixed-point unit of an opacity: 2^24, so that N 2^24 stays below 2^53 for boxes
/// of up to 2^29 voxels (a radius of 400 voxels on every axis).
constexpr double kOpacityUnit = 16777216.0;

/// The opacity in fixed point, or NaN where the function is undefined (log scale).
inline float fixedOpacity(const OpacityFunction& function, double value)
{
  return static_cast<float>(std::nearbyint(evaluateOpacity(function, value) * kOpacityUnit));
}

/// Pass 1: every voxel's fixed-point opacity into `alpha` (the volume's dims, x fastest).
/// False when cancelled; `undefined` is set where the function gave NaN.
template <class T>
bool writeOpacities(const VolumeView& view, const OpacityFunction& function, float* alpha,
  std::atomic<bool>& undefined, const Execution& execution)
{
  const TypedVolume<T> volume(view);
  constexpr bool tabulated = std::is_integral<T>::value && sizeof(T) <= 2;
  // 8- and 16-bit data: one evaluation per possible value, then a lookup per voxel.
  std::vector<float> table;
  if constexpr (tabulated)
  {
    constexpr std::int64_t lowest = std::numeric_limits<T>::min();
    constexpr std::int64_t count = std::int64_t(std::numeric_limits<T>::max()) - lowest + 1;
    table.resize(static_cast<std::size_t>(count));
    for (std::int64_t i = 0; i < count; ++i)
      table[static_cast<std::size_t>(i)] = fixedOpacity(function, static_cast<double>(lowest + i));
  }
  const std::int64_t nx = view.dims[0];
  const std::int64_t ny = view.dims[1];
  const int threads = resolveThreadCount(execution.threads);
  return parallelFor(view.dims[2], threads, threads, execution,
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress)
    {
      bool nan = false;
      for (std::int64_t z = begin; z < end; ++z)
      {
        for (std::int64_t y = 0; y < ny; ++y)
        {
          const T* in = volume.row(y, z);
          float* out = alpha + volume.index(0, y, z);
          for (std::int64_t x = 0; x < nx; ++x)
          {
            const T v = in[x * volume.stride];
            if constexpr (tabulated)
              out[x] =
                table[static_cast<std::size_t>(std::int64_t(v) - std::numeric_limits<T>::min())];
            else
              out[x] = fixedOpacity(function, static_cast<double>(v));
            nan = nan || std::isnan(out[x]);
          }
        }
        if (!progress.advance())
          break;
      }
      if (nan)
        undefined.store(true, std::memory_order_relaxed);
    });
}

/// Pass 2: the box sums of the fixed-point opacities, turned into O_tf.
bool writeOpenness(const VolumeView& alphaView, const Region& region, const Radius& radius,
  float* openness, const Execution& execution)
{
  const TypedVolume<float> alpha(alphaView);
  const BoxGeometry geometry(alphaView.dims, region, radius);
  const std::vector<std::int64_t> countX = geometry.windowCounts(0);
  const std::vector<std::int64_t> countY = geometry.windowCounts(1);
  const MomentScale exact{ 0.0, 0.0 }; // no shift: the sums stay integers
  const std::int64_t nx = region.size[0];
  const std::int64_t ny = region.size[1];
  return streamMoments<float, double>(alpha, geometry, exact, false, execution,
    [&]
    {
      return [&](const MomentSlice<float, double>& slice)
      {
        float* out = openness + (slice.z - region.begin[2]) * nx * ny;
        for (std::int64_t y = 0; y < ny; ++y)
        {
          const double rowCount = static_cast<double>(countY[y] * slice.countZ) * kOpacityUnit;
          const double* sums = slice.sum + y * nx;
          for (std::int64_t x = 0; x < nx; ++x)
          {
            const double total = rowCount * static_cast<double>(countX[x]);
            out[y * nx + x] = static_cast<float>((total - sums[x]) / total);
          }
        }
      };
    });
}

} // namespace

Status computeTransferFunctionOpenness(const VolumeView& volume, const Region& region,
  const Radius& radius, const OpacityFunction& function, float* openness,
  const Execution& execution)
{
  StorageArray<float> alpha;
  alpha.resize(static_cast<std::size_t>(volume.voxelCount()));
  std::atomic<bool> undefined{ false };
  const bool written = dispatchScalarType(volume.type,
    [&](auto tag)
    {
      return writeOpacities<decltype(tag)>(
        volume, function, alpha.data(), undefined, stageExecution(execution, 0.0, 0.3));
    });
  if (!written)
    return Status::cancelled();
  if (undefined.load())
    return Status::failure(
      "the opacity function is undefined at some of the values: its log scale needs "
      "values and points above 0");
  VolumeView alphaView;
  alphaView.data = alpha.data();
  alphaView.type = ScalarType::Float32;
  alphaView.dims = volume.dims;
  return writeOpenness(alphaView, region, radius, openness, stageExecution(execution, 0.3, 1.0))
    ? Status::success()
    : Status::cancelled();
}

} // namespace detail
} // namespace vao
