// Pinned staging for the host-device copies (only the CUDA backend's headers include it).
// The host arrays are the caller's, pageable; a copy from or to pageable memory makes the
// driver stage it synchronously through a small pinned buffer of its own. Here the CPU's
// threads copy into (out of) pinned buffers of ours and the DMA engines move those
// asynchronously, two buffers taking turns so that the CPU fills one while the other
// travels. The buffers, the streams and the device buffers of the fused pass live in one
// cache per device, kept across calls and grown when a call needs more.
#pragma once

#include "cuda/common/DeviceMemory.h"

#include "VolumeAccess.h"
#include "cpu/common/Parallel.h"

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
      check(cudaHostAlloc(reinterpret_cast<void**>(&this->Data), bytes, cudaHostAllocDefault),
        "pinned allocation");
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

/// What one device keeps between calls: the fused pass's device buffers, the pinned
/// pieces each way, the streams (upload, compute, download).
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
  // Never destroyed: freeing pinned and device memory from a static destructor would race
  // the CUDA runtime's own teardown at exit; the process's end frees both.
  static std::mutex* guard = new std::mutex;
  static auto* caches = new std::map<int, std::unique_ptr<TransferCache>>;
  std::lock_guard<std::mutex> lock(*guard);
  std::unique_ptr<TransferCache>& cache = (*caches)[index];
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
  detail::parallelFor(pieces, static_cast<int>(pieces), threads,
    [&](std::int64_t begin, std::int64_t end)
    {
      const Index lo = begin * kPiece, hi = gpu::lower(bytes, end * kPiece);
      std::memcpy(to + lo, from + lo, static_cast<std::size_t>(hi - lo));
    });
}

/// Rows [begin, end) of the region's block (a row: sx values along x; row r is block
/// slice r / sy, row r % sy), gathered from the volume into `to`.
template <class T>
void gatherRows(const detail::TypedVolume<T>& volume, const Region& region,
  const gpu::RegionGeometry& g, Index begin, Index end, T* to, int threads)
{
  const Index x0 = region.begin[0] - g.ox, y0 = region.begin[1] - g.oy, z0 = region.begin[2] - g.oz;
  const Index rows = end - begin;
  detail::parallelFor(rows, static_cast<int>(gpu::lower<Index>(rows, 64)), threads,
    [&](std::int64_t lo, std::int64_t hi)
    {
      for (Index k = lo; k < hi; ++k)
      {
        const Index row = begin + k;
        const Index z = z0 + row / g.sy, y = y0 + row % g.sy;
        T* out = to + k * g.sx;
        if (volume.stride == 1)
          std::memcpy(
            out, volume.data + (z * volume.dims[1] + y) * volume.dims[0] + x0, g.sx * sizeof(T));
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

/// Milliseconds between two recorded events.
float elapsed(cudaEvent_t start, cudaEvent_t stop)
{
  float ms = 0.0f;
  check(cudaEventElapsedTime(&ms, start, stop), "event time");
  return ms;
}

/// Bytes of one staged piece: large enough for the link's full rate, small enough that
/// the first piece starts soon and the pinned memory stays small (four pieces a device).
constexpr Index kStagedPiece = Index(8) << 20;

/// Copies between the host and the device through two pinned buffers of one piece each,
/// taking turns on one stream: the CPU fills (empties) one while the other travels. It
/// adds up the time the copies themselves took (CUDA events around each piece).
class PinnedPipe
{
public:
  PinnedPipe(PinnedBuffer (&buffers)[2], cudaStream_t stream)
    : Stream(stream)
  {
    for (int b = 0; b < 2; ++b)
      this->Buffers[b] = buffers[b].reserve(static_cast<std::size_t>(kStagedPiece));
  }

  /// Queues `units` units of `unitBytes` for `device`; fill(begin, end, to) writes units
  /// [begin, end) into pinned memory. Returns when the last piece is queued (finish()
  /// waits for it); the stream's earlier work runs first.
  template <class Fill>
  void up(unsigned char* device, Index units, Index unitBytes, const Fill& fill)
  {
    const Index per = gpu::greater<Index>(1, kStagedPiece / unitBytes);
    if (per * unitBytes > kStagedPiece) // a unit beyond a piece: the buffers grow for it
      this->grow(unitBytes);
    for (Index u = 0; u < units; u += per)
    {
      const Index n = gpu::lower(per, units - u);
      const int slot = this->take();
      fill(u, u + n, this->Buffers[slot]);
      this->send(
        slot, device + u * unitBytes, this->Buffers[slot], n * unitBytes, cudaMemcpyHostToDevice);
    }
  }

  /// Copies `bytes` of `device` to `host` after the stream's earlier work; returns when
  /// they are on the host.
  void down(unsigned char* host, const unsigned char* device, Index bytes, int threads)
  {
    const Index pieces = (bytes + kStagedPiece - 1) / kStagedPiece;
    Index copied = 0;
    const auto copyOut = [&](Index piece)
    {
      const int slot = static_cast<int>(piece % 2);
      this->wait(slot);
      const Index at = piece * kStagedPiece;
      parallelCopy(host + at, this->Buffers[slot], gpu::lower(kStagedPiece, bytes - at), threads);
      copied = piece + 1;
    };
    for (Index piece = 0; piece < pieces; ++piece)
    {
      const int slot = static_cast<int>(piece % 2);
      if (piece >= 2)
        copyOut(piece - 2);
      const Index at = piece * kStagedPiece;
      this->send(slot, this->Buffers[slot], device + at, gpu::lower(kStagedPiece, bytes - at),
        cudaMemcpyDeviceToHost);
    }
    for (Index piece = copied; piece < pieces; ++piece)
      copyOut(piece);
  }

  /// Waits for every piece still travelling.
  void finish()
  {
    for (int slot = 0; slot < 2; ++slot)
      this->wait(slot);
  }

  double bytes() const { return this->Bytes; }
  double milliseconds() const { return this->Milliseconds; }

private:
  /// A free slot: the older of the two, once its piece has arrived.
  int take()
  {
    const int slot = static_cast<int>(this->Turn++ % 2);
    this->wait(slot);
    return slot;
  }
  void wait(int slot)
  {
    if (!this->Busy[slot])
      return;
    check(cudaEventSynchronize(this->Done[slot].event), "copy");
    this->Milliseconds += elapsed(this->Start[slot].event, this->Done[slot].event);
    this->Busy[slot] = false;
  }
  void send(int slot, void* to, const void* from, Index bytes, cudaMemcpyKind kind)
  {
    check(cudaEventRecord(this->Start[slot].event, this->Stream), "event record");
    check(cudaMemcpyAsync(to, from, static_cast<std::size_t>(bytes), kind, this->Stream),
      kind == cudaMemcpyHostToDevice ? "upload" : "download");
    check(cudaEventRecord(this->Done[slot].event, this->Stream), "event record");
    this->Busy[slot] = true;
    this->Bytes += static_cast<double>(bytes);
  }
  void grow(Index bytes)
  {
    this->finish();
    for (int b = 0; b < 2; ++b)
    {
      this->Owned[b].reset(new PinnedBuffer);
      this->Buffers[b] = this->Owned[b]->reserve(static_cast<std::size_t>(bytes));
    }
  }

  cudaStream_t Stream;
  unsigned char* Buffers[2];
  std::unique_ptr<PinnedBuffer> Owned[2]; // only for units beyond a piece
  Event Start[2], Done[2];
  bool Busy[2] = { false, false };
  Index Turn = 0;
  double Bytes = 0.0;
  double Milliseconds = 0.0;
};

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
  PinnedPipe upPipe() { return PinnedPipe(cache.stagingIn, cache.streams[0]); }
  PinnedPipe downPipe() { return PinnedPipe(cache.stagingOut, cache.streams[2]); }
};

TransferCache& currentTransferCache()
{
  int device = 0;
  check(cudaGetDevice(&device), "device");
  return transferCache(device);
}

/// The region's block, from the volume to `device`, through pinned pieces; returns when it
/// is on the device.
template <class T>
void uploadBlock(const detail::TypedVolume<T>& volume, const Region& region,
  const gpu::RegionGeometry& g, T* device, int threads)
{
  StagedCopy copy(currentTransferCache());
  PinnedPipe pipe = copy.upPipe();
  pipe.up(reinterpret_cast<unsigned char*>(device), g.sy * g.sz,
    g.sx * static_cast<Index>(sizeof(T)),
    [&](Index begin, Index end, unsigned char* to)
    { gatherRows(volume, region, g, begin, end, reinterpret_cast<T*>(to), threads); });
  pipe.finish();
}

/// `bytes` from `device` to `host` through pinned pieces, after the work queued on the
/// default stream (the kernels that wrote them).
void stagedDownload(unsigned char* host, const unsigned char* device, Index bytes, int threads)
{
  check(cudaStreamSynchronize(nullptr), "passes");
  StagedCopy copy(currentTransferCache());
  copy.downPipe().down(host, device, bytes, threads);
}

} // namespace
} // namespace cuda
} // namespace vao
