// The smoothed query of every voxel of a region (SmoothedQuery.cxx).
#pragma once

#include "vao/AmbientOcclusion.h"

namespace vao
{
namespace detail
{

/// q(x) of docs/methods.md section 9 for the region's voxels (x fastest) with sigma in voxels, the
/// window clipped to the volume. Returns false when cancelled.
bool computeSmoothedQuery(const VolumeView& volume, const Region& region, double sigma,
  double* query, const Execution& execution);

} // namespace detail
} // namespace vao
