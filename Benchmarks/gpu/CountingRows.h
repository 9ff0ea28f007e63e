// The GPU benchmark's rows for the counting methods: Histogram CDF at its default bins and
// Exact Box, each at R = 10 on the device, with the bars of the issue that name them
// (Histogram's kernels against the Gaussian CDF's; Exact Box's kernels, and its result
// equal to the CPU's on a slab of the volume, where the CPU's O(R^3) count stays short).
#pragma once

#include "GpuBenchmarkSupport.h"

#include "vao/AmbientOcclusion.h"
#include "vao/Cuda.h"
#include "vao/HistogramCdf.h"

#include <cstdint>
#include <string>
#include <vector>

namespace gpubench
{

/// `gaussianKernelMs`: the Gaussian CDF's kernels at R = 10 on the same volume (< 0: not
/// measured); `bars`: whether this volume is the one the bars name.
inline void benchmarkCounting(const vao::VolumeView& view, const std::string& label, int repeat,
  double gaussianKernelMs, bool withBars)
{
  constexpr int kRadius = 10;
  const vao::Region whole = vao::Region::whole(view);
  std::vector<float> openness(static_cast<std::size_t>(whole.voxelCount()));
  vao::AmbientOcclusionParameters histogram;
  histogram.method = vao::Method::HistogramCdf;
  histogram.radius = { kRadius, kRadius, kRadius };
  if (!vao::volumeThresholds(view, 64, histogram.thresholds).ok)
  {
    bar("SKIP", label + ": Histogram CDF (no thresholds)");
    return;
  }
  vao::AmbientOcclusionParameters exact;
  exact.method = vao::Method::ExactBox;
  exact.radius = histogram.radius;
  struct Row
  {
    const char* name;
    const vao::AmbientOcclusionParameters& p;
    int repeat;
  };
  for (const Row& row :
    { Row{ "Histogram CDF (64 bins)", histogram, repeat }, Row{ "Exact Box", exact, 2 } })
  {
    const GpuTimes t = timeGpu(
      [&](vao::cuda::Timing* timing)
      {
        return vao::cuda::computeAmbientOcclusion(
          view, whole, row.p, { openness.data(), nullptr }, {}, timing);
      },
      row.repeat);
    if (!t.ok)
    {
      std::printf("  %-26s %3d  GPU call failed: %s\n", row.name, kRadius, t.message.c_str());
      callFailed = true;
      continue;
    }
    std::printf("  %-26s %3d %12.3f %15.3f\n", row.name, kRadius, t.kernelMs, t.totalMs);
    if (!withBars)
      continue;
    if (row.p.method == vao::Method::HistogramCdf && gaussianKernelMs > 0)
      bar(t.kernelMs <= 4.0 * gaussianKernelMs ? "PASS" : "FAIL",
        format("%s R=10 Histogram CDF kernels %.3f ms <= 4x the Gaussian CDF's (%.3f ms): %.2fx",
          label.c_str(), t.kernelMs, gaussianKernelMs, t.kernelMs / gaussianKernelMs));
    if (row.p.method == vao::Method::ExactBox)
      bar(t.kernelMs <= 100.0 ? "PASS" : "FAIL",
        format("%s R=10 Exact Box kernels %.3f ms <= 100 ms", label.c_str(), t.kernelMs));
  }
  if (!withBars)
    return;
  // Equality with the CPU on a slab of 16 slices in the middle (boxes clipped to the whole
  // volume, as in a distributed piece).
  const std::int64_t depth = std::min<std::int64_t>(16, view.dims[2]);
  const vao::Region slab{ { 0, 0, (view.dims[2] - depth) / 2 },
    { view.dims[0], view.dims[1], depth } };
  const std::size_t n = static_cast<std::size_t>(slab.voxelCount());
  std::vector<float> gpu(n, -1.0f), cpu(n);
  const vao::Status device =
    vao::cuda::computeAmbientOcclusion(view, slab, exact, { gpu.data(), nullptr });
  const vao::Status host = vao::computeAmbientOcclusion(view, slab, exact, { cpu.data(), nullptr });
  if (!device.ok || !host.ok)
  {
    bar("FAIL",
      label +
        " R=10 Exact Box equals the CPU: a call failed: " + (device.ok ? host : device).message);
    return;
  }
  std::size_t differ = 0;
  for (std::size_t i = 0; i < n; ++i)
    differ += gpu[i] != cpu[i];
  bar(differ == 0 ? "PASS" : "FAIL",
    format("%s R=10 Exact Box equals the CPU bit for bit on %lld slices: %zu of %zu voxels differ",
      label.c_str(), static_cast<long long>(depth), differ, n));
}

} // namespace gpubench
