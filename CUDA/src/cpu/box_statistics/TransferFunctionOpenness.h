// The Transfer Function method on the CPU (TransferFunctionOpenness.cxx).
#pragma once

#include "vao/AmbientOcclusion.h"
#include "vao/TransferFunction.h"

namespace vao
{
namespace detail
{

/// O_tf = 1 - the mean opacity of the clipped box, for every region voxel
/// (docs/methods.md section 10), and their range into `range` unless it is null. The
/// function must pass checkOpacityFunction.
Status computeTransferFunctionOpenness(const VolumeView& volume, const Region& region,
  const Radius& radius, const OpacityFunction& function, float* openness, OutputRange* range,
  const Execution& execution);

} // namespace detail
} // namespace vao
