// The O(R^3) references of Ruiz et al.: the fraction of the clipped box (or inscribed
// ellipsoid) whose values are <= the query. Used as the oracle of the estimators.
#pragma once

#include "vao/AmbientOcclusion.h"

#include <cstdint>
#include <vector>

namespace vao
{
namespace detail
{

/// Half-width along x of every row of the neighbourhood, at (dz + Rz) (2 Ry + 1) + (dy + Ry):
/// Rx for the box; for the ellipsoid (sphere) the voxels with sum_i (d_i / R_i)^2 <= 1 (an
/// axis with R_i = 0 admits d_i = 0 only, voxels on the surface are in), -1 for a row
/// outside it. The CPU and the device count over the same rows.
std::vector<std::int64_t> neighbourhoodRowHalfWidths(const Radius& radius, bool sphere);

/// `query`: the query of each region voxel (x fastest), or null for the voxel's own value
/// or the iso value (parameters.queryMode).
Status computeExactOpenness(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, const double* query, float* openness,
  const Execution& execution);

} // namespace detail
} // namespace vao
