// How a surface query (SurfaceSampling.cxx) walks its points. On whole levels it takes
// them all at once. On a SurfacePyramid's tiled levels it sweeps them in slabs along z,
// one layer of level 0's tiles each: a slab marks the tiles its samples reach, gives back
// the tiles out of use that the sweep has left behind while more than the pyramid's
// keptBytes are built, builds the new ones and samples. The tiles held at once are then
// those near one slab plus what the pyramid keeps, instead of all that the surface reaches (on the
// bone surface of a CT head, 73% of the int16 input). Each point's result depends on its own
// samples only, so the order changes no bit.
#pragma once

#include "cpu/moment_pyramid/LevelTiles.h"
#include "cpu/moment_pyramid/SurfaceBatches.h"

#include <cstdint>
#include <limits>
#include <vector>

namespace vao
{
namespace detail
{

/// The points ordered by the layer of level-0 tiles that holds them (a counting sort),
/// and where each layer's points begin (one more entry than layers).
struct SlabOrder
{
  std::vector<std::uint32_t> order;
  std::vector<std::int64_t> begin;
};

template <class P>
SlabOrder slabOrder(const LevelTiles& level, const P* points, std::int64_t count)
{
  SlabOrder slabs;
  const std::int64_t layers = level.layerCount();
  slabs.begin.assign(static_cast<std::size_t>(layers + 1), 0);
  for (std::int64_t i = 0; i < count; ++i)
    ++slabs.begin[level.layerOf(static_cast<double>(points[3 * i + 2])) + 1];
  for (std::int64_t l = 0; l < layers; ++l)
    slabs.begin[l + 1] += slabs.begin[l];
  slabs.order.resize(static_cast<std::size_t>(count));
  std::vector<std::int64_t> next(slabs.begin.begin(), slabs.begin.end() - 1);
  for (std::int64_t i = 0; i < count; ++i)
    slabs.order[next[level.layerOf(static_cast<double>(points[3 * i + 2]))]++] =
      static_cast<std::uint32_t>(i);
  return slabs;
}

/// sample(lanes) for every batch of the points. With `tiles`, slab by slab: first
/// mark(lanes, *tiles) for the slab's batches, the layers left behind released, and the
/// marked tiles built. Progress: each slab its share of the points (marking
/// the first tenth of it, building to 0.3, sampling the rest). Returns false when
/// cancelled.
template <class P, class Mark, class Sample>
bool sweepPoints(PyramidTiles* tiles, const P* points, const P* normals, std::int64_t count,
  const Execution& execution, Mark&& mark, Sample&& sample)
{
  if (!tiles)
  {
    return forEachBatch(points, normals, PointRange{ nullptr, 0, count }, execution, sample);
  }
  // More points than 32-bit indices name (a surface of 48 GiB of float points): one slab.
  SlabOrder slabs;
  if (count <= std::numeric_limits<std::uint32_t>::max())
    slabs = slabOrder(*tiles->at(0), points, count);
  else
    slabs.begin = { 0, count };
  const std::int64_t slabCount = static_cast<std::int64_t>(slabs.begin.size()) - 1;
  tiles->settle();
  const bool up = tiles->upward;
  tiles->upward = !up;
  std::int64_t done = 0;
  for (std::int64_t s = 0; s < slabCount; ++s)
  {
    const std::size_t i = static_cast<std::size_t>(up ? s : slabCount - 1 - s);
    const PointRange range{ slabs.order.empty() ? nullptr : slabs.order.data(), slabs.begin[i],
      slabs.begin[i + 1] - slabs.begin[i] };
    if (range.count == 0)
      continue;
    const Execution slab = stageExecution(execution, static_cast<double>(done) / count,
      static_cast<double>(done + range.count) / count);
    done += range.count;
    tiles->forgetMarks();
    if (!forEachBatch(points, normals, range, stageExecution(slab, 0.0, 0.1),
          [&](const PointLanes& lanes) { mark(lanes, *tiles); }))
    {
      return false;
    }
    // What the slab does not reach goes before its new tiles come.
    tiles->releaseBehind(up);
    if (!tiles->buildMarked(stageExecution(slab, 0.1, 0.3)) ||
      !forEachBatch(points, normals, range, stageExecution(slab, 0.3, 1.0), sample))
    {
      return false;
    }
  }
  // Every layer is behind the sweep now.
  tiles->forgetMarks();
  tiles->releaseBehind(up);
  return true;
}

} // namespace detail
} // namespace vao
