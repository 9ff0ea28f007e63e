// The GPU benchmark's row for the variance occlusion pyramid: 4 levels of a 256^3 int16
// volume built on the device (kernels and end to end) and on the CPU, the levels compared
// (1e-5), and the bar on the kernels (Penner & Mitchell's Table 1 had it on a 2008
// GPU in 8.6 ms).
#pragma once

#include "GpuBenchmarkSupport.h"

#include "vao/Cuda.h"
#include "vao/VarianceOcclusionMap.h"

#include <cmath>
#include <cstdint>
#include <vector>

namespace gpubench
{

inline void benchmarkPyramid(
  const std::vector<std::int16_t>& volume, const vao::Index3& dims, int repeat)
{
  vao::VolumeView view;
  view.data = volume.data();
  view.type = vao::ScalarType::Int16;
  view.dims = dims;
  const std::array<double, 3> origin = { 0, 0, 0 }, spacing = { 1, 1, 1 };
  const vao::PyramidParameters parameters; // 4 levels from full resolution
  std::vector<vao::MomentLevel> gpu, cpu;
  const GpuTimes t = timeGpu([&](vao::cuda::Timing* timing)
    { return vao::cuda::buildMomentPyramid(view, origin, spacing, parameters, gpu, {}, timing); },
    repeat);
  const double cpuMs =
    timeCpu([&] { return vao::buildMomentPyramid(view, origin, spacing, parameters, cpu); },
      std::min(repeat, 3));
  std::printf("\n== variance occlusion pyramid, %lldx%lldx%lld int16, 4 levels\n",
    static_cast<long long>(dims[0]), static_cast<long long>(dims[1]),
    static_cast<long long>(dims[2]));
  if (!t.ok)
  {
    std::printf("  GPU call failed: %s\n", t.message.c_str());
    callFailed = true;
    bar("FAIL", "pyramid 256^3 4 levels on the device: the call failed: " + t.message);
    return;
  }
  std::printf("  kernels %.3f ms, end to end %.3f ms; CPU %.1f ms\n", t.kernelMs, t.totalMs, cpuMs);
  double worst = 0.0;
  bool same = gpu.size() == cpu.size();
  for (std::size_t l = 0; same && l < cpu.size(); ++l)
  {
    same = gpu[l].dims == cpu[l].dims;
    for (std::size_t i = 0; same && i < cpu[l].mean.size(); ++i)
    {
      const double mean = cpu[l].mean[i], variance = cpu[l].variance[i];
      worst = std::max(worst, std::abs(gpu[l].mean[i] - mean) / std::max(1.0, std::abs(mean)));
      worst = std::max(worst, std::abs(gpu[l].variance[i] - variance) / std::max(1.0, variance));
    }
  }
  bar(same && worst <= 1e-5 ? "PASS" : "FAIL",
    format("pyramid 256^3: the device's levels equal the CPU's to 1e-5 (largest relative "
           "difference %.3g%s)",
      worst, same ? "" : "; the levels' sizes differ"));
  bar(t.kernelMs <= 2.0 ? "PASS" : "FAIL",
    format("pyramid 256^3 4 levels kernels %.3f ms <= 2 ms", t.kernelMs));
}

} // namespace gpubench
