// The CUDA interface in a build without CUDA: nothing is available, every call says so.
#include "vao/Cuda.h"

namespace vao
{
namespace cuda
{

bool built()
{
  return false;
}

DeviceStatus deviceStatus(int)
{
  return { false, -1, "this build has no CUDA backend (VAO_ENABLE_CUDA off or no CUDA compiler)" };
}

Status computeAmbientOcclusion(const VolumeView&, const Region&, const AmbientOcclusionParameters&,
  const AmbientOcclusionOutput&, const Execution&, Timing*)
{
  return Status::device("no CUDA device: " + deviceStatus().description);
}

Status computeBoxStatistics(const VolumeView&, const Region&, const Radius&,
  const BoxStatisticsOutput&, const Execution&, Timing*)
{
  return Status::device("no CUDA device: " + deviceStatus().description);
}

Status buildMomentPyramid(const VolumeView&, const std::array<double, 3>&,
  const std::array<double, 3>&, const PyramidParameters&, std::vector<MomentLevel>& pyramid,
  const Execution&, Timing*)
{
  pyramid.clear();
  return Status::device("no CUDA device: " + deviceStatus().description);
}

void injectDeviceFailures(int) {}

double measureCopyBandwidth(double)
{
  return 0.0;
}

} // namespace cuda
} // namespace vao
