// The ranges of an output array, computed by the workers in one pass: per component, and
// of the tuples' Euclidean norms. The VTK filters hand them to VTK's range cache, so that
// ParaView's data information (every array's range, each component's and the norm's,
// after every update) does not scan a large output again on one thread.
#pragma once

#include <cstdint>
#include <vector>

namespace vao
{

struct ValueRanges
{
  std::vector<double> components; // min, max of component c at 2c, 2c + 1
  // Of sqrt(sum over the tuple's components of v^2), summed in double in component order;
  // NaN for one component (VTK then reports the component's range as the norm's).
  double norm[2] = { 0.0, 0.0 };
};

/// The ranges of `tuples` tuples of `components` floats (x fastest, components
/// interleaved), on `threads` threads (0: the default). Returns false, with `ranges`
/// unspecified, when there is no tuple or any value is not finite: the caller then lets
/// VTK compute its own ranges, whose treatment of NaN and infinity this does not repeat.
bool computeFiniteValueRanges(
  const float* values, std::int64_t tuples, int components, ValueRanges& ranges, int threads = 0);

} // namespace vao
