// The O(R^3) references of Ruiz et al.: the fraction of the clipped box (or inscribed
// ellipsoid) whose values are <= the query. Used as the oracle of the estimators.
#pragma once

#include "vao/AmbientOcclusion.h"

namespace vao
{
namespace detail
{

Status computeExactOpenness(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, float* openness, const Execution& execution);

} // namespace detail
} // namespace vao
