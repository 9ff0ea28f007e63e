// The CUDA backend of the kernel library: the same computations as AmbientOcclusion.h on
// an NVIDIA GPU, with the same formulas (Estimators.h) and the same numbers.
//
// Every function exists in every build: without CUDA (VAO_ENABLE_CUDA off or no nvcc)
// built() is false, deviceStatus() says why and the compute functions return a failure,
// so callers fall back to the CPU without #ifdefs. Errors of the device (no device, out
// of memory, launch failure) come back as a failed Status with CUDA's message, never as
// a crash.
#pragma once

#include "vao/AmbientOcclusion.h"
#include "vao/VarianceOcclusionMap.h"

#include <string>
#include <vector>

namespace vao
{
namespace cuda
{

/// True when the library was compiled with the CUDA backend.
bool built();

struct DeviceStatus
{
  bool available = false;
  int index = -1;          // among the visible devices
  std::string description; // which device, its name and memory; or why there is none
};

/// The device a call runs on among the `count` visible ones (CUDA_VISIBLE_DEVICES applies
/// first): `requested` when it is >= 0, else the process's rank on its node modulo
/// `count`, so that the ranks of a multi-GPU node spread over its devices. -1 when there
/// is no device or `requested` is not below `count`.
int chooseDevice(int requested, int count, int nodeLocalRank);

/// The device that Execution::device = `requested` selects (chooseDevice with the
/// launcher's node-local rank), and whether it is usable. The devices are queried once.
DeviceStatus deviceStatus(int requested = -1);

/// Time of one device pass, with the bytes it reads and writes, for bandwidth reports.
struct PassTiming
{
  std::string name;
  double milliseconds = 0.0;
  double bytes = 0.0;
};

/// Where the time of one call went (CUDA events for the kernels, wall clock overall).
/// Reset by every call that receives it; totalMilliseconds is set on success only.
struct Timing
{
  double kernelMilliseconds = 0.0; // all kernels, measured with CUDA events
  double totalMilliseconds = 0.0;  // the whole call: allocation, transfers, kernels
  std::vector<PassTiming> passes;
  // The host-device copies of the calls that stream z slabs (the fused pass): bytes each
  // way and the time the copies themselves took (CUDA events; they overlap the kernels,
  // so these are not parts of totalMilliseconds). Zero for the other calls.
  double uploadBytes = 0.0;
  double uploadMilliseconds = 0.0;
  double downloadBytes = 0.0;
  double downloadMilliseconds = 0.0;
};

/// Openness (and optionally the variance) of every voxel of the region, on the GPU. A
/// failure of the device (none, a CUDA error) has Status::deviceFailure set: the CPU
/// function may still succeed; bad input fails here as it would there.
/// Execution: the device (Execution::device, see deviceStatus), progress and cancellation
/// between stages (a running kernel is not interrupted); the thread count is that of the
/// CPU's copies into and out of the pinned staging buffers (the fused pass's slabs).
/// Every method runs here (the exact references by brute force, one thread per voxel);
/// the smoothed query runs on the CPU only.
Status computeAmbientOcclusion(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, const AmbientOcclusionOutput& output,
  const Execution& execution = {}, Timing* timing = nullptr);

/// Count, mean, variance, minimum and maximum over each voxel's clipped box, on the GPU.
Status computeBoxStatistics(const VolumeView& volume, const Region& region, const Radius& radius,
  const BoxStatisticsOutput& output, const Execution& execution = {}, Timing* timing = nullptr);

/// The moment pyramid of VarianceOcclusionMap.h, built on the device: the same checks,
/// levels and geometry as vao::buildMomentPyramid, each level's sums tap for tap the CPU's
/// (equal to 1e-5, the CPU's fused multiply-adds aside), downloaded into `pyramid`. On a
/// failure (Status::deviceFailure for the device's) the pyramid is left empty.
Status buildMomentPyramid(const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const PyramidParameters& parameters,
  std::vector<MomentLevel>& pyramid, const Execution& execution = {}, Timing* timing = nullptr);

/// For tests of the fallback to the CPU: the next `calls` computations on the device fail
/// once their input is on the device, as a device error would (Status::deviceFailure, a
/// message that says it was injected). 0 clears it. No effect without a device.
void injectDeviceFailures(int calls);

/// Device-to-device copy bandwidth in GB/s over a buffer of `bytes`, counting the bytes
/// read plus those written (as PassTiming::bytes does): the reference the passes are
/// compared with. 0 without a device.
double measureCopyBandwidth(double bytes);

} // namespace cuda
} // namespace vao
