// Typed access to a VolumeView, the scalar-type dispatch and the exact-accumulation traits.
#pragma once

#include "vao/AmbientOcclusion.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <type_traits>

namespace vao
{
namespace detail
{

/// Calls f(T{}) with T the C++ type of `type`.
template <class F>
auto dispatchScalarType(ScalarType type, F&& f)
{
  switch (type)
  {
    case ScalarType::Int8:
      return f(std::int8_t{});
    case ScalarType::UInt8:
      return f(std::uint8_t{});
    case ScalarType::Int16:
      return f(std::int16_t{});
    case ScalarType::UInt16:
      return f(std::uint16_t{});
    case ScalarType::Int32:
      return f(std::int32_t{});
    case ScalarType::UInt32:
      return f(std::uint32_t{});
    case ScalarType::Int64:
      return f(std::int64_t{});
    case ScalarType::UInt64:
      return f(std::uint64_t{});
    case ScalarType::Float64:
      return f(double{});
    case ScalarType::Float32:
    default:
      return f(float{});
  }
}

/// Sums of v and v^2 are exact in int64 for types of up to 16 bits (v^2 <= 2^32, so boxes
/// of up to 2^31 voxels fit); wider types accumulate in double after a shift by a
/// representative value, which removes the catastrophic cancellation of E[v^2] - mu^2.
template <class T>
struct MomentTraits
{
  static constexpr bool exactInteger = std::is_integral<T>::value && sizeof(T) <= 2;
  using Accumulator = typename std::conditional<exactInteger, std::int64_t, double>::type;
};

/// Read-only typed view of the volume: value(x, y, z) with the voxel stride applied.
template <class T>
struct TypedVolume
{
  const T* data;
  Index3 dims;
  std::int64_t stride;

  explicit TypedVolume(const VolumeView& view)
    : data(static_cast<const T*>(view.data))
    , dims(view.dims)
    , stride(view.voxelStride)
  {
  }

  std::int64_t index(std::int64_t x, std::int64_t y, std::int64_t z) const
  {
    return (z * dims[1] + y) * dims[0] + x;
  }
  T value(std::int64_t x, std::int64_t y, std::int64_t z) const
  {
    return data[index(x, y, z) * stride];
  }
  /// Pointer to the start of row (y, z); consecutive voxels are `stride` elements apart.
  const T* row(std::int64_t y, std::int64_t z) const { return data + index(0, y, z) * stride; }
};

/// The sampled voxels of `region` (momentShiftSamples): every step-th voxel of the data
/// set, step = max(1, n / 65536), in the data set's x-fastest order.
template <class T>
ShiftSamples shiftSamples(
  const TypedVolume<T>& volume, const Region& region, const Index3& offset, const Index3& whole)
{
  const std::int64_t n = whole[0] * whole[1] * whole[2];
  const std::int64_t step = std::max<std::int64_t>(1, n / 65536);
  ShiftSamples samples;
  for (std::int64_t z = region.begin[2]; z < region.begin[2] + region.size[2]; ++z)
    for (std::int64_t y = region.begin[1]; y < region.begin[1] + region.size[1]; ++y)
    {
      // The row's first sampled voxel: its index in the data set a multiple of step.
      const std::int64_t rowStart =
        ((z + offset[2]) * whole[1] + (y + offset[1])) * whole[0] + offset[0];
      const std::int64_t first = rowStart + region.begin[0];
      std::int64_t x = region.begin[0] + (step - first % step) % step;
      for (; x < region.begin[0] + region.size[0]; x += step, ++samples.count)
        samples.sum += static_cast<double>(volume.value(x, y, z));
    }
  return samples;
}

/// Mean of up to ~65k evenly spaced voxels: the shift that keeps squared sums small.
template <class T>
double sampledMean(const TypedVolume<T>& volume)
{
  const ShiftSamples samples =
    shiftSamples(volume, { { 0, 0, 0 }, volume.dims }, { 0, 0, 0 }, volume.dims);
  return samples.count > 0 ? samples.sum / samples.count : 0.0;
}

/// How a volume's box moments are accumulated: the value subtracted before squaring, and
/// the variance the sums' rounding can give a flat box (Estimators.h, sumRoundingVariance).
struct MomentScale
{
  double shift = 0.0;
  double roundingVariance = 0.0;
};

/// No shift and no rounding for exact integer sums (so the sums, and everything after
/// them, do not depend on which piece of the volume a run holds); for double sums the
/// basis given (a data set's, for its pieces) or else a sampled mean of the volume and the
/// rounding of values in [lowest, highest] about it.
template <class T>
MomentScale momentScale(
  const TypedVolume<T>& volume, double lowest, double highest, const MomentBasis& basis = {})
{
  if (MomentTraits<T>::exactInteger)
  {
    return {};
  }
  const bool given =
    std::isfinite(basis.shift) && std::isfinite(basis.lowest) && std::isfinite(basis.highest);
  const double shift = given ? basis.shift : sampledMean(volume);
  if (given)
  {
    lowest = std::min(lowest, basis.lowest);
    highest = std::max(highest, basis.highest);
  }
  const double deviation = std::max(std::abs(highest - shift), std::abs(lowest - shift));
  return { shift, sumRoundingVariance(deviation) };
}

/// The clipped span [lo, hi) of input indices that the region [begin, begin + size)
/// reads along one axis of n voxels with half-width r.
struct AxisSpan
{
  std::int64_t lo;
  std::int64_t hi;
  std::int64_t size() const { return hi - lo; }
};

inline AxisSpan readSpan(std::int64_t begin, std::int64_t size, std::int64_t r, std::int64_t n)
{
  return { std::max<std::int64_t>(0, begin - r), std::min<std::int64_t>(n, begin + size + r) };
}

} // namespace detail
} // namespace vao
