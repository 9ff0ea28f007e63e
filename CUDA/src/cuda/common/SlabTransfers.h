// The fused pass with overlapped transfers (only CudaBackend.cu includes it). Three
// streams (upload, compute, download) with events between them: while slab i computes,
// the host brings slab i - 1's outputs down and then sends chunk i + 1 up, each through
// two pinned pieces taking turns (PinnedStaging.h), so the kernels overlap the transfers
// and the CPU's copies overlap the DMA. The device buffers live in the device's
// TransferCache: a filter that runs again on the same volume allocates nothing.
#pragma once

#include "cuda/CudaExecutor.h"
#include "cuda/box_statistics/FusedStatistics.h"
#include "cuda/common/SlabPlan.h"

#include "VolumeAccess.h"
#include "cpu/common/Parallel.h"

#include <cuda_runtime.h>

#include <memory>
#include <vector>

namespace vao
{
namespace cuda
{
namespace
{

/// The outputs in FinalOutputs' order: openness, variance, count, mean, varianceD,
/// minimum, maximum.
constexpr int kFusedOutputs = 7;

/// One output array of the region: where it goes on the host and its element size.
struct OutputArray
{
  unsigned char* host;
  Index elementSize;
};

/// Events of one slab: its chunk uploaded, its kernel's start and end.
struct SlabEvents
{
  Event uploaded, kernelStart, kernel;
};

/// The fused pass over the region in slabs, transfers overlapped; `outputs` (null: not
/// asked for) in FinalOutputs' order. withExtrema: the box extrema too (CDF
/// Reconstruction, the statistics' minimum and maximum).
template <class T, class Acc>
void runFusedSlabs(const detail::TypedVolume<T>& volume, const Region& region, const gpu::RegionGeometry& g,
  Acc shift, const gpu::EstimatorSetting& estimator, bool withExtrema, const OutputArray (&outputs)[kFusedOutputs],
  const Execution& execution, Timing* timing, void (*afterFirstUpload)())
{
  StagedCopy copy(currentTransferCache()); // the device's buffers, drained on every exit
  TransferCache& cache = copy.cache;
  PinnedPipe up = copy.upPipe(), down = copy.downPipe();
  const cudaStream_t upStream = cache.streams[0], computeStream = cache.streams[1], downStream = cache.streams[2];

  const Index plane = g.rx * g.ry;
  const Index segment = gpu::segmentLength(g.radius[2]);
  const std::vector<gpu::SlabStep> plan = gpu::planSlabs(g, gpu::slabSlices(g, segment));
  // The device outputs, one array each, 256-byte aligned, region-sized.
  Index offsets[kFusedOutputs] = {}, outputBytes = 0, perVoxel = 0;
  for (int a = 0; a < kFusedOutputs; ++a)
  {
    offsets[a] = outputBytes;
    if (outputs[a].host)
    {
      perVoxel += outputs[a].elementSize;
      outputBytes += (g.region() * outputs[a].elementSize + 255) / 256 * 256;
    }
  }
  T* input = reinterpret_cast<T*>(cache.input.reserve(g.block() * static_cast<Index>(sizeof(T))));
  unsigned char* device = cache.outputs.reserve(outputBytes);
  const auto at = [&](int a) { return outputs[a].host ? device + offsets[a] : nullptr; };
  const gpu::FinalOutputs out{ reinterpret_cast<float*>(at(0)), reinterpret_cast<float*>(at(1)),
    reinterpret_cast<double*>(at(2)), reinterpret_cast<double*>(at(3)), reinterpret_cast<double*>(at(4)),
    reinterpret_cast<double*>(at(5)), reinterpret_cast<double*>(at(6)) };
  const gpu::StatisticsWriter<T, Acc> writer{ nullptr, nullptr, input, g, shift, estimator, out };
  const Index rowBytes = g.sx * static_cast<Index>(sizeof(T));

  std::vector<std::unique_ptr<SlabEvents>> events;
  // Slab i's outputs to the caller's arrays, once its kernel is done.
  const auto download = [&](std::size_t i) {
    const gpu::SlabStep& s = plan[i];
    check(cudaStreamWaitEvent(downStream, events[i]->kernel.event, 0), "stream wait");
    for (int a = 0; a < kFusedOutputs; ++a)
    {
      if (!outputs[a].host)
        continue;
      const Index first = s.sliceBegin * plane * outputs[a].elementSize;
      down.down(outputs[a].host + first, at(a) + first, (s.sliceEnd - s.sliceBegin) * plane * outputs[a].elementSize,
        execution.threads);
    }
  };
  for (std::size_t i = 0; i < plan.size(); ++i)
  {
    const gpu::SlabStep& s = plan[i];
    events.emplace_back(new SlabEvents);
    SlabEvents& e = *events.back();
    const Index firstRow = s.chunkBegin * g.sy;
    up.up(reinterpret_cast<unsigned char*>(input) + firstRow * rowBytes, (s.chunkEnd - s.chunkBegin) * g.sy, rowBytes,
      [&](Index begin, Index end, unsigned char* to) {
        gatherRows(volume, region, g, firstRow + begin, firstRow + end, reinterpret_cast<T*>(to), execution.threads);
      });
    check(cudaEventRecord(e.uploaded.event, upStream), "event record");
    if (i == 0 && afterFirstUpload)
      afterFirstUpload();

    check(cudaStreamWaitEvent(computeStream, e.uploaded.event, 0), "stream wait");
    check(cudaEventRecord(e.kernelStart.event, computeStream), "event record");
    if (withExtrema)
      launchFusedBlocks(gpu::fusedStatisticsWithExtrema(writer, s.sliceBegin, s.sliceEnd, segment), computeStream);
    else
      launchFusedBlocks(gpu::fusedStatistics(writer, s.sliceBegin, s.sliceEnd, segment), computeStream);
    check(cudaGetLastError(), "fused statistics");
    check(cudaEventRecord(e.kernel.event, computeStream), "event record");

    if (i >= 1)
      download(i - 1); // while slab i computes
    if (execution.progress)
      execution.progress(0.1 + 0.85 * static_cast<double>(i + 1) / plan.size());
    if (execution.abortRequested && execution.abortRequested())
      throw Cancelled{};
  }
  download(plan.size() - 1);
  up.finish();

  if (timing)
  {
    double kernelMs = 0.0;
    for (const auto& e : events)
      kernelMs += elapsed(e->kernelStart.event, e->kernel.event);
    timing->passes.push_back({ withExtrema ? "fused statistics and extrema" : "fused statistics", kernelMs,
      static_cast<double>(g.block() * sizeof(T) + g.region() * perVoxel) });
    timing->kernelMilliseconds += kernelMs;
    timing->uploadBytes += up.bytes();
    timing->uploadMilliseconds += up.milliseconds();
    timing->downloadBytes += down.bytes();
    timing->downloadMilliseconds += down.milliseconds();
  }
}

} // namespace
} // namespace cuda
} // namespace vao
