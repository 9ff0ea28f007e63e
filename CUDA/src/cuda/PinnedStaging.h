// Pinned staging for the host-device copies (only the CUDA backend's headers include it).
// The host arrays are the caller's, pageable; a copy from or to pageable memory makes the
// driver stage it synchronously through a small pinned buffer of its own. Here the CPU's
// threads copy into (out of) pinned buffers of ours and the DMA engines move those
// asynchronously, two buffers taking turns so that the CPU fills one while the other
// travels. The buffers, the streams and the device buffers of the fused pass live in one
// cache per device, kept across calls and grown when a call needs more.
#pragma once

#include "DeviceMemory.h"

#include "VolumeAccess.h"
#include "cpu/Parallel.h"

#include <cuda_runtime.h>

#include <cstring>
#include <map>
#include <memory>
#include <mutex>

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

/// Rows [begin, end) of the region's block (a row: sx values along x; row r is block
/// slice r / sy, row r % sy), gathered from the volume into `to`.
template <class T>
void gatherRows(const detail::TypedVolume<T>& volume, const Region& region, const gpu::RegionGeometry& g,
  Index begin, Index end, T* to, int threads)
{
  const Index x0 = region.begin[0] - g.ox, y0 = region.begin[1] - g.oy, z0 = region.begin[2] - g.oz;
  const Index rows = end - begin;
  detail::parallelFor(rows, static_cast<int>(gpu::lower<Index>(rows, 64)), threads, [&](std::int64_t lo, std::int64_t hi) {
    for (Index k = lo; k < hi; ++k)
    {
      const Index row = begin + k;
      const Index z = z0 + row / g.sy, y = y0 + row % g.sy;
      T* out = to + k * g.sx;
      if (volume.stride == 1)
        std::memcpy(out, volume.data + (z * volume.dims[1] + y) * volume.dims[0] + x0, g.sx * sizeof(T));
      else
        for (Index x = 0; x < g.sx; ++x)
          out[x] = volume.value(x0 + x, y, z);
    }
  });
}

/// A CUDA event, destroyed with the object.
struct Event
{
  cudaEvent_t event = nullptr;
  Event() { check(cudaEventCreate(&event), "event"); }
  ~Event() { cudaEventDestroy(event); }
  Event(const Event&) = delete;
  Event& operator=(const Event&) = delete;
};

/// Bytes of one staged piece: large enough for the link's full rate, small enough that
/// the first piece starts soon.
constexpr Index kStagedPiece = Index(8) << 20;

/// The current device's cache, held by one call (a staged copy, or the fused pass's slabs)
/// and drained before it is let go, on every exit.
struct StagedCopy
{
  TransferCache& cache;
  std::lock_guard<std::mutex> lock;
  explicit StagedCopy(TransferCache& c)
    : cache(c)
    , lock(c.busy)
  {
    cache.createStreams();
  }
  ~StagedCopy() { cache.drain(); }
};

TransferCache& currentTransferCache()
{
  int device = 0;
  check(cudaGetDevice(&device), "device");
  return transferCache(device);
}

/// Uploads `units` units of `unitBytes` to `device` through pinned pieces; fill(begin,
/// end, to) writes units [begin, end) of the source into pinned memory. Returns when the
/// data is on the device.
template <class Fill>
void stagedUpload(unsigned char* device, Index units, Index unitBytes, const Fill& fill)
{
  if (units <= 0)
    return;
  StagedCopy copy(currentTransferCache());
  const Index per = gpu::greater<Index>(1, kStagedPiece / unitBytes);
  unsigned char* buffers[2] = { copy.cache.stagingIn[0].reserve(static_cast<std::size_t>(per * unitBytes)),
    copy.cache.stagingIn[1].reserve(static_cast<std::size_t>(per * unitBytes)) };
  Event sent[2];
  const cudaStream_t stream = copy.cache.streams[0];
  Index piece = 0;
  for (Index u = 0; u < units; u += per, ++piece)
  {
    const Index n = gpu::lower(per, units - u);
    if (piece >= 2)
      check(cudaEventSynchronize(sent[piece % 2].event), "upload");
    fill(u, u + n, buffers[piece % 2]);
    check(cudaMemcpyAsync(device + u * unitBytes, buffers[piece % 2], static_cast<std::size_t>(n * unitBytes),
            cudaMemcpyHostToDevice, stream),
      "upload");
    check(cudaEventRecord(sent[piece % 2].event, stream), "event record");
  }
  check(cudaStreamSynchronize(stream), "upload");
}

/// The region's block, from the volume to `device`, through pinned pieces.
template <class T>
void uploadBlock(const detail::TypedVolume<T>& volume, const Region& region, const gpu::RegionGeometry& g, T* device,
  int threads)
{
  stagedUpload(reinterpret_cast<unsigned char*>(device), g.sy * g.sz, g.sx * static_cast<Index>(sizeof(T)),
    [&](Index begin, Index end, unsigned char* to) {
      gatherRows(volume, region, g, begin, end, reinterpret_cast<T*>(to), threads);
    });
}

/// `bytes` from `device` to `host` through pinned pieces, after the work queued on the
/// default stream (the kernels that wrote them).
void stagedDownload(unsigned char* host, const unsigned char* device, Index bytes, int threads)
{
  if (bytes <= 0)
    return;
  check(cudaStreamSynchronize(nullptr), "passes");
  StagedCopy copy(currentTransferCache());
  unsigned char* buffers[2] = { copy.cache.stagingOut[0].reserve(static_cast<std::size_t>(kStagedPiece)),
    copy.cache.stagingOut[1].reserve(static_cast<std::size_t>(kStagedPiece)) };
  Event arrived[2];
  const cudaStream_t stream = copy.cache.streams[2];
  const Index pieces = (bytes + kStagedPiece - 1) / kStagedPiece;
  auto copyOut = [&](Index piece) {
    check(cudaEventSynchronize(arrived[piece % 2].event), "download");
    const Index at = piece * kStagedPiece;
    parallelCopy(host + at, buffers[piece % 2], gpu::lower(kStagedPiece, bytes - at), threads);
  };
  for (Index piece = 0; piece < pieces; ++piece)
  {
    if (piece >= 2)
      copyOut(piece - 2);
    const Index at = piece * kStagedPiece;
    check(cudaMemcpyAsync(buffers[piece % 2], device + at, static_cast<std::size_t>(gpu::lower(kStagedPiece, bytes - at)),
            cudaMemcpyDeviceToHost, stream),
      "download");
    check(cudaEventRecord(arrived[piece % 2].event, stream), "event record");
  }
  for (Index piece = gpu::greater<Index>(0, pieces - 2); piece < pieces; ++piece)
    copyOut(piece);
}

} // namespace
} // namespace cuda
} // namespace vao
