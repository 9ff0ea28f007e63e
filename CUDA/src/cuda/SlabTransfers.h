// The fused pass with overlapped transfers (only CudaBackend.cu includes it): each chunk
// of the block is copied by the CPU's threads into a pinned staging buffer and uploaded
// from there asynchronously, each slab's outputs come back into another and are copied out
// by the CPU (PinnedStaging.h). Three streams (upload, compute, download) with events
// between them let chunk i + 1 travel up and slab i - 1 travel down while slab i computes;
// two staging buffers each way let the CPU fill one while the other is in flight. The
// buffers live in the device's TransferCache: a filter that runs again on the same volume
// allocates nothing.
#pragma once

#include "CudaExecutor.h"
#include "FusedStatistics.h"
#include "SlabPlan.h"

#include "VolumeAccess.h"
#include "cpu/Parallel.h"

#include <cuda_runtime.h>

#include <memory>
#include <vector>

namespace vao
{
namespace cuda
{
namespace
{

/// Events of one slab: its upload, kernel and download, each with a start.
struct SlabEvents
{
  Event upStart, up, kernelStart, kernel, downStart, down;
};

float elapsed(cudaEvent_t start, cudaEvent_t stop)
{
  float ms = 0.0f;
  check(cudaEventElapsedTime(&ms, start, stop), "event time");
  return ms;
}

/// One output array of the region: where it goes on the host and its element size.
struct OutputArray
{
  unsigned char* host;
  Index elementSize;
};

/// The fused pass over the region in slabs, transfers overlapped; `outputs` in the order
/// of FinalOutputs' openness, variance, count, mean, varianceD (null: not asked for).
template <class T, class Acc>
void runFusedSlabs(const detail::TypedVolume<T>& volume, const Region& region, const gpu::RegionGeometry& g,
  Acc shift, const gpu::EstimatorSetting& estimator, const OutputArray (&outputs)[5], const Execution& execution,
  Timing* timing, void (*afterFirstUpload)())
{
  StagedCopy copy(currentTransferCache()); // the device's buffers, drained on every exit
  TransferCache& cache = copy.cache;
  cudaStream_t upStream = cache.streams[0], computeStream = cache.streams[1], downStream = cache.streams[2];

  const Index plane = g.rx * g.ry;
  const Index segment = gpu::segmentLength(g.radius[2]);
  const std::vector<gpu::SlabStep> plan = gpu::planSlabs(g, gpu::slabSlices(g, segment));
  Index chunkMost = 0, slabMost = 0, perVoxel = 0;
  for (const gpu::SlabStep& s : plan)
  {
    chunkMost = gpu::greater(chunkMost, s.chunkEnd - s.chunkBegin);
    slabMost = gpu::greater(slabMost, s.sliceEnd - s.sliceBegin);
  }
  // The device outputs, one array each, 256-byte aligned, region-sized.
  Index offsets[5] = {}, outputBytes = 0;
  for (int a = 0; a < 5; ++a)
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
  const Index chunkBytes = chunkMost * g.sx * g.sy * static_cast<Index>(sizeof(T));
  const Index slabBytes = slabMost * plane * perVoxel;
  unsigned char* stagingIn[2] = { cache.stagingIn[0].reserve(static_cast<std::size_t>(chunkBytes)),
    cache.stagingIn[1].reserve(static_cast<std::size_t>(chunkBytes)) };
  unsigned char* stagingOut[2] = { cache.stagingOut[0].reserve(static_cast<std::size_t>(slabBytes)),
    cache.stagingOut[1].reserve(static_cast<std::size_t>(slabBytes)) };

  auto at = [&](int a) { return outputs[a].host ? device + offsets[a] : nullptr; };
  const gpu::FinalOutputs out{ reinterpret_cast<float*>(at(0)), reinterpret_cast<float*>(at(1)),
    reinterpret_cast<double*>(at(2)), reinterpret_cast<double*>(at(3)), reinterpret_cast<double*>(at(4)), nullptr,
    nullptr };
  const gpu::StatisticsWriter<T, Acc> writer{ nullptr, nullptr, input, g, shift, estimator, out };
  std::vector<std::unique_ptr<SlabEvents>> events;
  // Slab i's outputs from its staging buffer to the caller's arrays.
  auto copyOut = [&](std::size_t i) {
    const gpu::SlabStep& s = plan[i];
    check(cudaEventSynchronize(events[i]->down.event), "download");
    const unsigned char* from = stagingOut[i % 2];
    for (int a = 0; a < 5; ++a)
    {
      if (!outputs[a].host)
        continue;
      const Index bytes = (s.sliceEnd - s.sliceBegin) * plane * outputs[a].elementSize;
      parallelCopy(outputs[a].host + s.sliceBegin * plane * outputs[a].elementSize, from, bytes, execution.threads);
      from += bytes;
    }
  };
  for (std::size_t i = 0; i < plan.size(); ++i)
  {
    const gpu::SlabStep& s = plan[i];
    events.emplace_back(new SlabEvents);
    SlabEvents& e = *events.back();
    if (i >= 2)
      check(cudaEventSynchronize(events[i - 2]->up.event), "upload"); // staging in[i % 2] is free
    T* staged = reinterpret_cast<T*>(stagingIn[i % 2]);
    gatherRows(volume, region, g, s.chunkBegin * g.sy, s.chunkEnd * g.sy, staged, execution.threads);
    const Index sliceValues = g.sx * g.sy;
    check(cudaEventRecord(e.upStart.event, upStream), "event record");
    check(cudaMemcpyAsync(input + s.chunkBegin * sliceValues, staged,
            static_cast<std::size_t>((s.chunkEnd - s.chunkBegin) * sliceValues) * sizeof(T), cudaMemcpyHostToDevice,
            upStream),
      "upload");
    check(cudaEventRecord(e.up.event, upStream), "event record");
    if (i == 0 && afterFirstUpload)
      afterFirstUpload();

    check(cudaStreamWaitEvent(computeStream, e.up.event, 0), "stream wait");
    check(cudaEventRecord(e.kernelStart.event, computeStream), "event record");
    launchFusedBlocks(gpu::fusedStatistics(writer, s.sliceBegin, s.sliceEnd, segment), computeStream);
    check(cudaGetLastError(), "fused statistics");
    check(cudaEventRecord(e.kernel.event, computeStream), "event record");

    if (i >= 2)
      copyOut(i - 2); // staging out[i % 2] is free
    check(cudaStreamWaitEvent(downStream, e.kernel.event, 0), "stream wait");
    check(cudaEventRecord(e.downStart.event, downStream), "event record");
    unsigned char* staging = stagingOut[i % 2];
    for (int a = 0; a < 5; ++a)
    {
      if (!outputs[a].host)
        continue;
      const Index bytes = (s.sliceEnd - s.sliceBegin) * plane * outputs[a].elementSize;
      check(cudaMemcpyAsync(staging, at(a) + s.sliceBegin * plane * outputs[a].elementSize,
              static_cast<std::size_t>(bytes), cudaMemcpyDeviceToHost, downStream),
        "download");
      staging += bytes;
    }
    check(cudaEventRecord(e.down.event, downStream), "event record");
    if (execution.progress)
      execution.progress(0.1 + 0.85 * static_cast<double>(i + 1) / plan.size());
    if (execution.abortRequested && execution.abortRequested())
      throw Cancelled{};
  }
  for (std::size_t i = plan.size() >= 2 ? plan.size() - 2 : 0; i < plan.size(); ++i)
    copyOut(i);

  if (timing)
  {
    double kernelMs = 0.0;
    for (std::size_t i = 0; i < plan.size(); ++i)
    {
      const gpu::SlabStep& s = plan[i];
      const SlabEvents& e = *events[i];
      kernelMs += elapsed(e.kernelStart.event, e.kernel.event);
      timing->uploadMilliseconds += elapsed(e.upStart.event, e.up.event);
      timing->downloadMilliseconds += elapsed(e.downStart.event, e.down.event);
      timing->uploadBytes += static_cast<double>((s.chunkEnd - s.chunkBegin) * g.sx * g.sy * sizeof(T));
      timing->downloadBytes += static_cast<double>((s.sliceEnd - s.sliceBegin) * plane * perVoxel);
    }
    timing->passes.push_back({ "fused statistics", kernelMs, static_cast<double>(g.block() * sizeof(T) + g.region() * perVoxel) });
    timing->kernelMilliseconds += kernelMs;
  }
}

} // namespace
} // namespace cuda
} // namespace vao
