// The Transfer Function method: O_tf(x) = 1 - (1/N) sum over the clipped box of alpha(v).
//
// The opacities are summed in fixed point, round(alpha * 2^24) as an int32, with the box
// sums of MomentPlanes.h (sums of v only, in int64): integer sums are exact in any order,
// so they do not depend on threads or on how a distributed run cut the volume, and
// O_tf = (N 2^24 - S) / (N 2^24) rounds once. The fixed point costs at most 2^-25 per voxel
// (3e-8, within the 1e-6 the method promises), and a 0/1 opacity (a step at c) is exact:
// the result is then Exact Box's with the iso value c, bit for bit.
//
// 8- and 16-bit data: the opacity of every possible value is tabulated once, and the box
// sums read each row through the table (TabulatedRows), so no opacity volume is stored.
// Other types (and a log-scale function undefined at some 8/16-bit values): a first pass
// writes every voxel's fixed-point opacity, evaluated once per voxel, and reports a value
// where the function is undefined.
#include "cpu/box_statistics/TransferFunctionOpenness.h"

#include "cpu/box_statistics/MomentPlanes.h"
#include "cpu/common/ConcurrentRange.h"
#include "cpu/common/Parallel.h"
#include "cpu/simd/CpuDispatch.h"
#include "vao/Storage.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdint>
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

/// The opacity in fixed point; -1 where the function is undefined (log scale).
inline std::int32_t fixedOpacity(const OpacityFunction& function, double value)
{
  const double alpha = evaluateOpacity(function, value);
  return std::isnan(alpha) ? -1 : static_cast<std::int32_t>(std::nearbyint(alpha * kOpacityUnit));
}

template <class T>
constexpr bool kTabulated = std::is_integral<T>::value && sizeof(T) <= 2;

/// The fixed-point opacity of every value of an 8- or 16-bit type, indexed by v - min.
template <class T>
std::vector<std::int32_t> opacityTable(const OpacityFunction& function)
{
  constexpr std::int64_t lowest = std::numeric_limits<T>::min();
  constexpr std::int64_t count = std::int64_t(std::numeric_limits<T>::max()) - lowest + 1;
  std::vector<std::int32_t> table(static_cast<std::size_t>(count));
  for (std::int64_t i = 0; i < count; ++i)
    table[static_cast<std::size_t>(i)] = fixedOpacity(function, static_cast<double>(lowest + i));
  return table;
}

/// out[i] = byValue[in[i * stride]]: a row through the table (byValue indexed by the
/// value itself). Compiled for AVX2 and AVX-512 too (gathers).
template <class T>
struct TableLookup
{
  static VAO_ALWAYS_INLINE void run(const T* __restrict in, std::int64_t stride,
    const std::int32_t* __restrict byValue, std::int32_t* __restrict out, std::int64_t n)
  {
    if (stride == 1)
      for (std::int64_t i = 0; i < n; ++i)
        out[i] = byValue[in[i]];
    else
      for (std::int64_t i = 0; i < n; ++i)
        out[i] = byValue[in[i * stride]];
  }
};

/// out[i] = 1 - sums[i] / (rowUnits countX[i]): O_tf of a row from its box sums, rowUnits
/// the y and z window sizes times the fixed-point unit. Compiled for AVX2 and AVX-512 too.
struct OpennessFromSums
{
  static VAO_ALWAYS_INLINE void run(const std::int64_t* __restrict sums,
    const double* __restrict countX, double rowUnits, float* __restrict out, std::int64_t n)
  {
    for (std::int64_t i = 0; i < n; ++i)
    {
      const double total = rowUnits * countX[i];
      out[i] = static_cast<float>((total - static_cast<double>(sums[i])) / total);
    }
  }
};

/// MomentPlanes' rows of fixed-point opacities read through the table (see VolumeRows).
template <class T>
struct TabulatedRows
{
  using Value = std::int32_t;
  static constexpr bool kScratch = true;
  const TypedVolume<T>& volume;
  const std::int32_t* table; // indexed by v - min
  SimdTier simd = cpuSimdTier();

  std::int64_t stride() const { return 1; }
  const std::int32_t* row(
    std::int64_t y, std::int64_t z, std::int64_t x0, std::int64_t n, std::int32_t* scratch) const
  {
    const std::int64_t s = this->volume.stride;
    const std::int32_t* byValue = this->table - std::int64_t(std::numeric_limits<T>::min());
    runRows<TableLookup<T>>(this->simd, this->volume.row(y, z) + x0 * s, s, byValue, scratch, n);
    return scratch;
  }
};

/// Every voxel's fixed-point opacity into `alpha` (the volume's dims, x fastest). False
/// when cancelled; `undefined` is set where the function is undefined.
template <class T>
bool writeOpacities(const VolumeView& view, const OpacityFunction& function, std::int32_t* alpha,
  std::atomic<bool>& undefined, const Execution& execution)
{
  const TypedVolume<T> volume(view);
  std::vector<std::int32_t> table;
  if constexpr (kTabulated<T>)
    table = opacityTable<T>(function);
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
          std::int32_t* out = alpha + volume.index(0, y, z);
          if constexpr (kTabulated<T>)
            TabulatedRows<T>{ volume, table.data() }.row(y, z, 0, nx, out);
          else
          {
            const T* in = volume.row(y, z);
            for (std::int64_t x = 0; x < nx; ++x)
              out[x] = fixedOpacity(function, static_cast<double>(in[x * volume.stride]));
          }
          nan = nan || *std::min_element(out, out + nx) < 0;
        }
        if (!progress.advance())
          break;
      }
      if (nan)
        undefined.store(true, std::memory_order_relaxed);
    });
}

/// The box sums of the fixed-point opacities `rows` gives, turned into O_tf; their range
/// into `range` where it is asked for (not null).
template <class Source>
bool writeOpenness(const Source& rows, const Index3& dims, const Region& region,
  const Radius& radius, float* openness, OutputRange* range, const Execution& execution)
{
  const BoxGeometry geometry(dims, region, radius);
  const std::vector<std::int64_t> countsX = geometry.windowCounts(0);
  const std::vector<double> countX(countsX.begin(), countsX.end());
  const std::vector<std::int64_t> countY = geometry.windowCounts(1);
  const SimdTier simd = cpuSimdTier();
  ConcurrentRange seen;
  const MomentScale exact{ 0.0, 0.0 }; // no shift: the sums stay integers
  const std::int64_t nx = region.size[0];
  const std::int64_t ny = region.size[1];
  const bool done = streamMomentsOf<std::int64_t>(rows, geometry, exact, false, execution,
    [&]
    {
      return [&](const MomentSlice<std::int32_t, std::int64_t>& slice)
      {
        float* out = openness + (slice.z - region.begin[2]) * nx * ny;
        for (std::int64_t y = 0; y < ny; ++y)
        {
          const double rowUnits = static_cast<double>(countY[y] * slice.countZ) * kOpacityUnit;
          runRows<OpennessFromSums>(
            simd, slice.sum + y * nx, countX.data(), rowUnits, out + y * nx, nx);
          if (range)
            seen.add(out + y * nx, nx);
        }
      };
    });
  if (done && range)
    *range = seen.result();
  return done;
}

const char* const kUndefined = "the opacity function is undefined at some of the values: its "
                               "log scale needs values and points above 0";

/// A first pass stores the opacities, then their box sums.
Status storedOpacities(const VolumeView& volume, const Region& region, const Radius& radius,
  const OpacityFunction& function, float* openness, OutputRange* range, const Execution& execution)
{
  StorageArray<std::int32_t> alpha;
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
    return Status::failure(kUndefined);
  VolumeView alphaView;
  alphaView.data = alpha.data();
  alphaView.type = ScalarType::Int32;
  alphaView.dims = volume.dims;
  const TypedVolume<std::int32_t> stored(alphaView);
  return writeOpenness(VolumeRows<std::int32_t>{ stored }, volume.dims, region, radius, openness,
           range, stageExecution(execution, 0.3, 1.0))
    ? Status::success()
    : Status::cancelled();
}

} // namespace

Status computeTransferFunctionOpenness(const VolumeView& volume, const Region& region,
  const Radius& radius, const OpacityFunction& function, float* openness, OutputRange* range,
  const Execution& execution)
{
  bool stored = false;
  const bool done = dispatchScalarType(volume.type,
    [&](auto tag)
    {
      using T = decltype(tag);
      if constexpr (kTabulated<T>)
      {
        const std::vector<std::int32_t> table = opacityTable<T>(function);
        if (std::find(table.begin(), table.end(), -1) == table.end())
        {
          const TypedVolume<T> values(volume);
          return writeOpenness(TabulatedRows<T>{ values, table.data() }, volume.dims, region,
            radius, openness, range, execution);
        }
      }
      stored = true; // undefined somewhere in the table: only the values present tell
      return true;
    });
  if (stored)
    return storedOpacities(volume, region, radius, function, openness, range, execution);
  return done ? Status::success() : Status::cancelled();
}

} // namespace detail
} // namespace vao
