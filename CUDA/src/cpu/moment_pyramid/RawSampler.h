// Trilinear values of the raw volume at world positions, clamped to its bounds: the
// definition of the half-voxel-inside query of surface ambient occlusion (docs/methods.md,
// Penner and Mitchell) and of sampleVolume. SurfaceLanes.h samples kLanes
// positions at once in vector registers with the same formula and the same bits.
#pragma once

#include "VolumeAccess.h"

#include <algorithm>
#include <array>
#include <cstdint>
#include <limits>

namespace vao
{
namespace detail
{

/// The divisions by the spacing and the strides done once for a query's many samples.
template <class T>
struct RawSampler
{
  const T* data;
  double origin[3], inverseSpacing[3], maxIndex[3];
  std::int64_t stride[3];
  // Every voxel's element index fits in 32 bits: the vector lanes' gathers apply.
  bool narrowIndices;

  RawSampler(const TypedVolume<T>& typed, const std::array<double, 3>& origin,
    const std::array<double, 3>& spacing)
    : data(typed.data)
  {
    for (int a = 0; a < 3; ++a)
    {
      this->origin[a] = origin[a];
      this->inverseSpacing[a] = 1.0 / spacing[a];
      this->maxIndex[a] = static_cast<double>(typed.dims[a] - 1);
    }
    this->stride[0] = typed.stride;
    this->stride[1] = typed.dims[0] * typed.stride;
    this->stride[2] = typed.dims[0] * typed.dims[1] * typed.stride;
    this->narrowIndices =
      this->stride[2] * typed.dims[2] <= std::numeric_limits<std::int32_t>::max();
  }

  /// The cell's lower corner, the steps to the upper one (0 where clamped) and the
  /// fractions f towards it; then nested blends v0 (1 - f) + v1 f along x, y, z.
  double operator()(const std::array<double, 3>& position) const
  {
    std::int64_t base = 0, step[3];
    double f[3];
    for (int a = 0; a < 3; ++a)
    {
      // max(0, ...) first: a position on the origin of a spacing whose inverse overflows
      // (a subnormal one) gives 0 * inf, NaN, which this takes to the first voxel.
      const double u =
        std::min(std::max(0.0, (position[a] - this->origin[a]) * this->inverseSpacing[a]),
          this->maxIndex[a]);
      const std::int64_t lower = static_cast<std::int64_t>(u); // u >= 0: truncation is the floor
      f[a] = u - static_cast<double>(lower);
      base += lower * this->stride[a];
      step[a] = u < this->maxIndex[a] ? this->stride[a] : 0;
    }
    const T* c = this->data + base;
    auto row = [&](std::int64_t i)
    { return static_cast<double>(c[i]) * (1 - f[0]) + static_cast<double>(c[i + step[0]]) * f[0]; };
    const double lowerPlane = row(0) * (1 - f[1]) + row(step[1]) * f[1];
    const double upperPlane = row(step[2]) * (1 - f[1]) + row(step[2] + step[1]) * f[1];
    return lowerPlane * (1 - f[2]) + upperPlane * f[2];
  }
};

} // namespace detail
} // namespace vao
