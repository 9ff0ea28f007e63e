// Output buffers and the comparisons the kernel tests apply to outputs: box statistics
// held in doubles, closeness relative to the reference, equality bit for bit.
#pragma once

#include "vao/AmbientOcclusion.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace vaotest
{

/// |a - b| within `tolerance` of the reference b, absolute below 1 (so that values near 0
/// are not held to an impossible relative bound).
inline bool closeRelative(double a, double b, double tolerance)
{
  return std::abs(a - b) <= tolerance * std::max(1.0, std::abs(b));
}

/// The same size and the same bytes: NaNs and signed zeros included, which == would not see.
template <class T>
bool sameBits(const std::vector<T>& a, const std::vector<T>& b)
{
  return a.size() == b.size() &&
    (a.empty() || std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0);
}

/// The five outputs of computeBoxStatistics for n voxels, each prefilled with `fill` (a
/// value no output has, where a test must see that every voxel was written).
struct StatsArrays
{
  std::vector<double> count, mean, variance, minimum, maximum;
  explicit StatsArrays(std::int64_t n, double fill = 0.0)
    : count(n, fill)
    , mean(n, fill)
    , variance(n, fill)
    , minimum(n, fill)
    , maximum(n, fill)
  {
  }
  vao::BoxStatisticsOutput output()
  {
    return { count.data(), mean.data(), variance.data(), minimum.data(), maximum.data() };
  }
};

} // namespace vaotest
