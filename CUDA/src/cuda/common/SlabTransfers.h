// The fused pass with overlapped transfers (only CudaBackend.cu includes it). Three
// streams (upload, compute, download) with events between them: while slab i computes,
// the host brings slab i - 1's outputs down and then sends chunk i + 1 up, each through
// two pinned pieces taking turns (PinnedStaging.h), so the kernels overlap the transfers
// and the CPU's copies overlap the DMA. The device buffers live in the device's
// TransferCache: a filter that runs again on the same volume allocates nothing.
#pragma once

#include "cuda/CudaExecutor.h"
#include "cuda/common/FusedStatistics.h"
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

/// Where the asked-for outputs lie in the device's output buffer: one array each, 256-byte
/// aligned and region-sized, so that a slab's share of each output is one copy down.
struct DeviceOutputs
{
  Index offsets[kFusedOutputs] = {};
  Index bytes = 0;               // the buffer's size
  Index perVoxel = 0;            // bytes of all the outputs together per region voxel
  unsigned char* base = nullptr; // the buffer (the TransferCache's outputs)

  /// Output a on the device; null where it is not asked for.
  unsigned char* at(const OutputArray (&outputs)[kFusedOutputs], int a) const
  {
    return outputs[a].host ? this->base + this->offsets[a] : nullptr;
  }

  /// The outputs as the kernel's writer takes them.
  gpu::FinalOutputs finalOutputs(const OutputArray (&outputs)[kFusedOutputs]) const
  {
    return { reinterpret_cast<float*>(this->at(outputs, 0)),
      reinterpret_cast<float*>(this->at(outputs, 1)),
      reinterpret_cast<double*>(this->at(outputs, 2)),
      reinterpret_cast<double*>(this->at(outputs, 3)),
      reinterpret_cast<double*>(this->at(outputs, 4)),
      reinterpret_cast<double*>(this->at(outputs, 5)),
      reinterpret_cast<double*>(this->at(outputs, 6)) };
  }
};

/// The layout of DeviceOutputs for `voxels` region voxels (its base still to be reserved).
inline DeviceOutputs layOutOutputs(const OutputArray (&outputs)[kFusedOutputs], Index voxels)
{
  DeviceOutputs device;
  for (int a = 0; a < kFusedOutputs; ++a)
  {
    device.offsets[a] = device.bytes;
    if (outputs[a].host)
    {
      device.perVoxel += outputs[a].elementSize;
      device.bytes += (voxels * outputs[a].elementSize + 255) / 256 * 256;
    }
  }
  return device;
}

/// Slab s's kernel on the compute stream: it waits for its chunk's upload (e.uploaded),
/// and e.kernelStart and e.kernel around it time it and tell the download when to start.
template <class T, class Acc>
void launchSlab(const gpu::StatisticsWriter<T, Acc>& writer, const gpu::SlabStep& s, Index segment,
  bool withExtrema, cudaStream_t computeStream, SlabEvents& e)
{
  check(cudaStreamWaitEvent(computeStream, e.uploaded.event, 0), "stream wait");
  check(cudaEventRecord(e.kernelStart.event, computeStream), "event record");
  if (withExtrema)
    launchFusedBlocks(
      gpu::fusedStatisticsWithExtrema(writer, s.sliceBegin, s.sliceEnd, segment), computeStream);
  else
    launchFusedBlocks(
      gpu::fusedStatistics(writer, s.sliceBegin, s.sliceEnd, segment), computeStream);
  check(cudaGetLastError(), "fused statistics");
  check(cudaEventRecord(e.kernel.event, computeStream), "event record");
}

/// Slab s's outputs to the caller's arrays, on the download stream once its kernel is done
/// (`kernelDone`): a slab is whole slices of `plane` voxels, one range of each output.
inline void downloadSlab(PinnedPipe& down, cudaStream_t downStream, cudaEvent_t kernelDone,
  const gpu::SlabStep& s, Index plane, const OutputArray (&outputs)[kFusedOutputs],
  const DeviceOutputs& device, int threads)
{
  check(cudaStreamWaitEvent(downStream, kernelDone, 0), "stream wait");
  for (int a = 0; a < kFusedOutputs; ++a)
  {
    if (!outputs[a].host)
      continue;
    const Index first = s.sliceBegin * plane * outputs[a].elementSize;
    down.down(outputs[a].host + first, device.at(outputs, a) + first,
      (s.sliceEnd - s.sliceBegin) * plane * outputs[a].elementSize, threads);
  }
}

/// The pass in `timing`: its kernel time, summed over each slab's own pair of events
/// (between slabs the compute stream waits for uploads, which one pair around the whole
/// pass would count), the bytes the kernels move (`kernelBytes`) and both pipes' transfers.
inline void addFusedTiming(Timing& timing, const std::vector<std::unique_ptr<SlabEvents>>& events,
  bool withExtrema, double kernelBytes, const PinnedPipe& up, const PinnedPipe& down)
{
  double kernelMs = 0.0;
  for (const auto& e : events)
    kernelMs += elapsed(e->kernelStart.event, e->kernel.event);
  timing.passes.push_back(
    { withExtrema ? "fused statistics and extrema" : "fused statistics", kernelMs, kernelBytes });
  timing.kernelMilliseconds += kernelMs;
  timing.uploadBytes += up.bytes();
  timing.uploadMilliseconds += up.milliseconds();
  timing.downloadBytes += down.bytes();
  timing.downloadMilliseconds += down.milliseconds();
}

/// The fused pass over the region in slabs, transfers overlapped; `outputs` (null: not
/// asked for) in FinalOutputs' order. withExtrema: the box extrema too (CDF
/// Reconstruction, the statistics' minimum and maximum). Each turn of the loop uploads
/// chunk i (the slices slab i reads), launches slab i behind it, and brings slab i - 1's
/// outputs down while slab i computes.
template <class T, class Acc>
void runFusedSlabs(const detail::TypedVolume<T>& volume, const Region& region,
  const gpu::RegionGeometry& g, Acc shift, const gpu::EstimatorSetting& estimator, bool withExtrema,
  const OutputArray (&outputs)[kFusedOutputs], const Execution& execution, Timing* timing,
  void (*afterFirstUpload)())
{
  StagedCopy copy(currentTransferCache()); // the device's buffers, drained on every exit
  TransferCache& cache = copy.cache;
  PinnedPipe up = copy.upPipe(), down = copy.downPipe();
  const cudaStream_t upStream = cache.streams[0], computeStream = cache.streams[1],
                     downStream = cache.streams[2];

  const Index plane = g.rx * g.ry;
  const Index segment = gpu::segmentLength(g.radius[2]);
  const std::vector<gpu::SlabStep> plan = gpu::planSlabs(g, gpu::slabSlices(g, segment));
  DeviceOutputs device = layOutOutputs(outputs, g.region());
  T* input = reinterpret_cast<T*>(cache.input.reserve(g.block() * static_cast<Index>(sizeof(T))));
  device.base = cache.outputs.reserve(device.bytes);
  const gpu::StatisticsWriter<T, Acc> writer{ nullptr, nullptr, input, g, shift, estimator,
    device.finalOutputs(outputs) };
  const Index rowBytes = g.sx * static_cast<Index>(sizeof(T));

  std::vector<std::unique_ptr<SlabEvents>> events;
  const auto download = [&](std::size_t i)
  {
    downloadSlab(down, downStream, events[i]->kernel.event, plan[i], plane, outputs, device,
      execution.threads);
  };
  for (std::size_t i = 0; i < plan.size(); ++i)
  {
    const gpu::SlabStep& s = plan[i];
    events.emplace_back(new SlabEvents);
    SlabEvents& e = *events.back();
    const Index firstRow = s.chunkBegin * g.sy;
    up.up(reinterpret_cast<unsigned char*>(input) + firstRow * rowBytes,
      (s.chunkEnd - s.chunkBegin) * g.sy, rowBytes,
      [&](Index begin, Index end, unsigned char* to)
      {
        gatherRows(volume, region, g, firstRow + begin, firstRow + end, reinterpret_cast<T*>(to),
          execution.threads);
      });
    check(cudaEventRecord(e.uploaded.event, upStream), "event record");
    if (i == 0 && afterFirstUpload)
      afterFirstUpload();

    launchSlab(writer, s, segment, withExtrema, computeStream, e);

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
    addFusedTiming(*timing, events, withExtrema,
      static_cast<double>(g.block() * sizeof(T) + g.region() * device.perVoxel), up, down);
}

} // namespace
} // namespace cuda
} // namespace vao
