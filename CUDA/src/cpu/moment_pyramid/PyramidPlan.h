// What every build of the moment pyramid shares, CPU (PyramidBuild.cxx) and device
// (CudaBackend.cu): the checks and the moments' shift, the kept voxels and the clipped
// weights of one level's blur, and the levels' geometry. The arithmetic of a blur is in
// PyramidRows.h (CPU) and PyramidPipeline.h (device), tap for tap the same.
#pragma once

#include "vao/VarianceOcclusionMap.h"

#include <cstdint>
#include <vector>

namespace vao
{
namespace detail
{

/// The checked request: the moments' shift K (the volume's sampled mean), the rounding
/// variance the levels record, and the step of level 0 (1, or 2 at half resolution).
struct PyramidSetup
{
  double shift = 0.0;
  double roundingVariance = 0.0;
  int firstStep = 1;
};

/// Checks the volume, geometry and parameters (the volume finite, its moments within
/// range) and fills `setup`; a failure says why.
Status preparePyramid(const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const PyramidParameters& parameters, PyramidSetup& setup);

/// The kept voxels per axis of a blur of `in` keeping every `step`-th voxel (1 or 2).
Index3 keptDims(const Index3& in, int step);

/// Normalised weights of the clipped 5-tap Gaussian for each kept output index along one
/// axis of n input voxels: weights[o * 5 + k] for input index o * step + k - 2 (0 where
/// that input is outside [0, n)).
std::vector<double> axisWeights(std::int64_t n, std::int64_t outN, int step);

/// Origin, spacing, kernel radius and rounding variance of every level (dims set).
void setLevelGeometry(std::vector<MomentLevel>& levels, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const PyramidSetup& setup);

} // namespace detail
} // namespace vao
