// Exact Rays on the CPU (ExactRays.cxx): the rays of docs/methods.md section 11, cast.
#pragma once

#include "vao/AmbientOcclusion.h"

#include <array>
#include <vector>

namespace vao
{
namespace detail
{

/// The n unit directions of the Fibonacci sphere, in world (x, y, z).
std::vector<std::array<double, 3>> fibonacciDirections(int n);

/// AO_ray of every region voxel: the mean over parameters.rays.rayCount directions of the
/// transmittance through sigma(v) = -ln(1 - min(alpha(v), 1 - 1e-6)) / u over the radius,
/// the value interpolated trilinearly at the midpoints of half-spacing steps, sigma 0
/// outside the volume block. Their range into `range` unless it is null. The parameters
/// must pass checkOpacityFunction and checkRayParameters.
Status computeExactRays(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, float* openness, OutputRange* range,
  const Execution& execution);

} // namespace detail
} // namespace vao
