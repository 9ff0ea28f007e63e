// The fused pass with overlapped transfers (only CudaBackend.cu includes it). The host
// arrays are the caller's, pageable: each chunk is copied by the CPU's threads into a
// pinned staging buffer and uploaded from there asynchronously, each slab's outputs come
// back into another and are copied out by the CPU, so no transfer touches pageable memory
// and the driver never stages a copy synchronously. Three streams (upload, compute,
// download) with events between them let chunk i + 1 travel up and slab i - 1 travel down
// while slab i computes; two staging buffers each way let the CPU fill one while the other
// is in flight.
//
// The staging and device buffers, streams and events live in one cache per device, kept
// across calls and grown when a call needs more: a filter that runs again on the same
// volume allocates nothing.
#pragma once

#include "CudaExecutor.h"
#include "FusedStatistics.h"
#include "SlabPlan.h"

#include "VolumeAccess.h"
#include "cpu/Parallel.h"

#include <cuda_runtime.h>

#include <cstring>
#include <map>
#include <memory>
#include <mutex>
#include <vector>

namespace vao
{
namespace cuda
{
namespace
{

/// A pinned (page-locked) host allocation.
class PinnedBuffer
{
public:
  PinnedBuffer() = default;
  ~PinnedBuffer() { cudaFreeHost(this->Data); }
  PinnedBuffer(const PinnedBuffer&) = delete;
  PinnedBuffer& operator=(const PinnedBuffer&) = delete;
  /// At least `bytes`, keeping the allocation when it is large enough.
  unsigned char* reserve(std::size_t bytes)
  {
    if (bytes > this->Size)
    {
      cudaFreeHost(this->Data);
      this->Data = nullptr;
      this->Size = 0;
      check(cudaHostAlloc(reinterpret_cast<void**>(&this->Data), bytes, cudaHostAllocDefault), "pinned allocation");
      this->Size = bytes;
    }
    return this->Data;
  }

private:
  unsigned char* Data = nullptr;
  std::size_t Size = 0;
};

/// A device allocation that grows on demand and is kept.
class GrowingDeviceBuffer
{
public:
  unsigned char* reserve(Index bytes)
  {
    if (bytes > this->Size)
    {
      this->Buffer = DeviceBuffer<unsigned char>(0); // free before allocating more
      this->Buffer = DeviceBuffer<unsigned char>(bytes);
      this->Size = bytes;
    }
    return this->Buffer.get();
  }

private:
  DeviceBuffer<unsigned char> Buffer{ 0 };
  Index Size = 0;
};

/// What one device keeps between calls of the fused pass.
struct TransferCache
{
  std::mutex busy; // one call at a time uses the buffers
  GrowingDeviceBuffer input, outputs;
  PinnedBuffer stagingIn[2], stagingOut[2];
  cudaStream_t streams[3] = { nullptr, nullptr, nullptr }; // upload, compute, download

  void createStreams()
  {
    for (cudaStream_t& stream : this->streams)
      if (!stream)
        check(cudaStreamCreateWithFlags(&stream, cudaStreamNonBlocking), "stream");
  }
  /// After a failure or Abort: nothing still in flight may use the buffers.
  void drain()
  {
    for (cudaStream_t stream : this->streams)
      if (stream)
        cudaStreamSynchronize(stream);
  }
};

/// The cache of device `index` (kept for the life of the process).
TransferCache& transferCache(int index)
{
  static std::mutex guard;
  static std::map<int, std::unique_ptr<TransferCache>> caches;
  std::lock_guard<std::mutex> lock(guard);
  std::unique_ptr<TransferCache>& cache = caches[index];
  if (!cache)
    cache.reset(new TransferCache);
  return *cache;
}

/// Events of one slab: its upload, kernel and download, each with a start.
struct SlabEvents
{
  cudaEvent_t upStart = nullptr, up = nullptr, kernelStart = nullptr, kernel = nullptr, downStart = nullptr,
              down = nullptr;
  SlabEvents()
  {
    for (cudaEvent_t* e : { &upStart, &up, &kernelStart, &kernel, &downStart, &down })
      check(cudaEventCreate(e), "event");
  }
  ~SlabEvents()
  {
    for (cudaEvent_t e : { upStart, up, kernelStart, kernel, downStart, down })
      if (e)
        cudaEventDestroy(e);
  }
  SlabEvents(const SlabEvents&) = delete;
  SlabEvents& operator=(const SlabEvents&) = delete;
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

/// Copies `bytes` between host buffers with the CPU's threads (the staging copies are the
/// part of a transfer the CPU does; one thread would not keep up with the link).
void parallelCopy(unsigned char* to, const unsigned char* from, Index bytes, int threads)
{
  constexpr Index kPiece = Index(1) << 20;
  const Index pieces = (bytes + kPiece - 1) / kPiece;
  detail::parallelFor(pieces, static_cast<int>(pieces), threads, [&](std::int64_t begin, std::int64_t end) {
    const Index lo = begin * kPiece, hi = gpu::lower(bytes, end * kPiece);
    std::memcpy(to + lo, from + lo, static_cast<std::size_t>(hi - lo));
  });
}

/// Block slices [begin, end) of the region's block, gathered from the volume into `to`.
template <class T>
void gatherChunk(const detail::TypedVolume<T>& volume, const Region& region, const gpu::RegionGeometry& g,
  Index begin, Index end, T* to, int threads)
{
  const Index x0 = region.begin[0] - g.ox, y0 = region.begin[1] - g.oy, z0 = region.begin[2] - g.oz;
  const Index rows = (end - begin) * g.sy;
  detail::parallelFor(rows, static_cast<int>(gpu::lower<Index>(rows, 64)), threads, [&](std::int64_t lo, std::int64_t hi) {
    for (Index row = lo; row < hi; ++row)
    {
      const Index z = z0 + begin + row / g.sy, y = y0 + row % g.sy;
      T* out = to + row * g.sx;
      if (volume.stride == 1)
        std::memcpy(out, volume.data + (z * volume.dims[1] + y) * volume.dims[0] + x0, g.sx * sizeof(T));
      else
        for (Index x = 0; x < g.sx; ++x)
          out[x] = volume.value(x0 + x, y, z);
    }
  });
}

/// The fused pass over the region in slabs, transfers overlapped; `outputs` in the order
/// of FinalOutputs' openness, variance, count, mean, varianceD (null: not asked for).
template <class T, class Acc>
void runFusedSlabs(const detail::TypedVolume<T>& volume, const Region& region, const gpu::RegionGeometry& g,
  Acc shift, const gpu::EstimatorSetting& estimator, const OutputArray (&outputs)[5], const Execution& execution,
  Timing* timing, void (*afterFirstUpload)())
{
  int deviceIndex = 0;
  check(cudaGetDevice(&deviceIndex), "device");
  TransferCache& cache = transferCache(deviceIndex);
  std::lock_guard<std::mutex> lock(cache.busy);
  struct Drain
  {
    TransferCache& cache;
    ~Drain() { cache.drain(); }
  } drainOnExit{ cache };
  cache.createStreams();
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
    check(cudaEventSynchronize(events[i]->down), "download");
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
      check(cudaEventSynchronize(events[i - 2]->up), "upload"); // staging in[i % 2] is free
    T* staged = reinterpret_cast<T*>(stagingIn[i % 2]);
    gatherChunk(volume, region, g, s.chunkBegin, s.chunkEnd, staged, execution.threads);
    const Index sliceValues = g.sx * g.sy;
    check(cudaEventRecord(e.upStart, upStream), "event record");
    check(cudaMemcpyAsync(input + s.chunkBegin * sliceValues, staged,
            static_cast<std::size_t>((s.chunkEnd - s.chunkBegin) * sliceValues) * sizeof(T), cudaMemcpyHostToDevice,
            upStream),
      "upload");
    check(cudaEventRecord(e.up, upStream), "event record");
    if (i == 0 && afterFirstUpload)
      afterFirstUpload();

    check(cudaStreamWaitEvent(computeStream, e.up, 0), "stream wait");
    check(cudaEventRecord(e.kernelStart, computeStream), "event record");
    launchFusedBlocks(gpu::fusedStatistics(writer, s.sliceBegin, s.sliceEnd, segment), computeStream);
    check(cudaGetLastError(), "fused statistics");
    check(cudaEventRecord(e.kernel, computeStream), "event record");

    if (i >= 2)
      copyOut(i - 2); // staging out[i % 2] is free
    check(cudaStreamWaitEvent(downStream, e.kernel, 0), "stream wait");
    check(cudaEventRecord(e.downStart, downStream), "event record");
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
    check(cudaEventRecord(e.down, downStream), "event record");
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
      kernelMs += elapsed(e.kernelStart, e.kernel);
      timing->uploadMilliseconds += elapsed(e.upStart, e.up);
      timing->downloadMilliseconds += elapsed(e.downStart, e.down);
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
