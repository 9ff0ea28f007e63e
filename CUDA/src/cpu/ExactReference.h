// The O(R^3) references of Ruiz et al.: the fraction of the clipped box (or inscribed
// ellipsoid) whose values are <= the query. Used as the oracle of the estimators.
#pragma once

#include "vao/AmbientOcclusion.h"

namespace vao
{
namespace detail
{

/// `query`: the query of each region voxel (x fastest), or null for the voxel's own value
/// or the iso value (parameters.queryMode).
Status computeExactOpenness(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, const double* query, float* openness, const Execution& execution);

} // namespace detail
} // namespace vao
