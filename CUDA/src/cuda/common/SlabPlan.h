// The order of the device's transfers for the fused pass: the region's slices cut into
// z slabs, and for each slab the chunk of the uploaded block that must be on the device
// before it runs. Chunks are disjoint and in order (no halo travels twice): slab i needs
// block slices up to its last slice plus rz, so chunk i is what slab i - 1 did not need.
// The CUDA side (SlabTransfers.h) uploads chunk i + 1 and downloads slab i - 1 while slab
// i computes; the tests check the plan on the host.
#pragma once

#include "cuda/common/Pipeline.h"

#include <vector>

namespace vao
{
namespace gpu
{

struct SlabStep
{
  Index sliceBegin; // region slices of the slab
  Index sliceEnd;
  Index chunkBegin; // block slices uploaded before it runs
  Index chunkEnd;
};

/// Slab thickness: about four slabs so that transfers overlap compute, each at least two
/// segments of the fused pass (so that a slab keeps the device busy and the first window
/// of a segment, 2 rz + 1 slices, stays a small part of the work).
inline Index slabSlices(const RegionGeometry& g, Index segment)
{
  const Index quarter = (g.rz + 3) / 4;
  return greater(quarter, 2 * segment);
}

inline std::vector<SlabStep> planSlabs(const RegionGeometry& g, Index slices)
{
  std::vector<SlabStep> plan;
  Index uploaded = 0;
  for (Index begin = 0; begin < g.rz; begin += slices)
  {
    const Index end = lower(begin + slices, g.rz);
    // The last slice's window ends at oz + end - 1 + rz; the last slab takes the rest.
    const Index needed = end == g.rz ? g.sz : lower(g.sz, g.oz + end + g.radius[2]);
    plan.push_back({ begin, end, uploaded, greater(uploaded, needed) });
    uploaded = plan.back().chunkEnd;
  }
  return plan;
}

} // namespace gpu
} // namespace vao
