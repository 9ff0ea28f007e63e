// The tiles of Histogram CDF on the CPU (HistogramTiles.h).
#include "cpu/histogram_cdf/HistogramTiles.h"

#include <algorithm>

namespace vao
{
namespace detail
{
namespace
{

/// Bytes of one worker's state for tiles grown by the radius to spanX x spanY pixels: their
/// window counts, one row of column sums, and the ring of the slices' bins with the
/// ranges of its rows.
std::int64_t tileStateBytes(
  std::int64_t spanX, std::int64_t spanY, const Radius& r, int lanes, int laneBytes)
{
  const int windowBytes = narrowWindow(r) ? 1 : laneBytes;
  return (spanX * spanY * windowBytes + spanX * laneBytes) * lanes +
    ringSlices(r) * (spanX + 2) * spanY * binBytes(lanes);
}

/// Tiles of `tiles` along an axis of n columns, as even as they can be: the longest's side.
std::int64_t evenSide(std::int64_t n, std::int64_t tiles)
{
  return (n + tiles - 1) / tiles;
}

} // namespace

TilePlan planTiles(const Index3& size, const Index3& dims, std::int64_t inputBytes, const Radius& r,
  int lanes, int laneBytes, int threads)
{
  constexpr std::int64_t kLargestSide = 256, kSmallestSide = 16;
  constexpr std::int64_t kSmallestBudget = std::int64_t(16) << 20;
  const std::int64_t budget = std::max(inputBytes / 5, kSmallestBudget);
  TilePlan best;
  double bestWork = 0;
  for (std::int64_t side = kLargestSide; side >= kSmallestSide; side -= 8)
  {
    TilePlan plan;
    plan.tilesX = std::max<std::int64_t>(1, (size[0] + side - 1) / side);
    plan.tilesY = std::max<std::int64_t>(1, (size[1] + side - 1) / side);
    plan.sideX = evenSide(size[0], plan.tilesX);
    plan.sideY = evenSide(size[1], plan.tilesY);
    plan.spanX = std::min(plan.sideX + 2 * std::int64_t(r.x), dims[0]);
    plan.spanY = std::min(plan.sideY + 2 * std::int64_t(r.y), dims[1]);
    const bool fits =
      threads * tileStateBytes(plan.spanX, plan.spanY, r, lanes, laneBytes) <= budget;
    if (!fits && side > kSmallestSide)
      continue;
    const std::int64_t tiles = plan.tilesX * plan.tilesY;
    const double pixels = double(plan.spanX) * double(plan.spanY);
    const double outputs = double(plan.sideX) * double(plan.sideY);
    for (std::int64_t parts = 1; parts <= std::min<std::int64_t>(size[2], 8 * threads); ++parts)
    {
      const std::int64_t slices = evenSide(size[2], parts);
      const std::int64_t rounds = (tiles * parts + threads - 1) / threads;
      const double work = double(rounds) *
        (outputs * double(slices) +
          pixels * double(slices + std::min<std::int64_t>(2 * std::int64_t(r.z), size[2])));
      if (best.zParts == 0 || work < bestWork)
      {
        best = plan;
        best.zParts = parts;
        bestWork = work;
      }
    }
  }
  return best;
}

} // namespace detail
} // namespace vao
