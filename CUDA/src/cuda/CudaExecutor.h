// The CUDA side of the GPU pipeline's executor (only CudaBackend.cu includes it): the
// kernel launchers and the slice transpose, and CudaExecutor, which runs Pipeline.h's
// passes on the device with optional timing.
#pragma once

#include "cuda/common/FusedStatistics.h"
#include "cuda/common/PinnedStaging.h"
#include "cuda/common/Pipeline.h"

#include "vao/Cuda.h"

#include <cuda_runtime.h>

#include <stdexcept>
#include <string>
#include <vector>

namespace vao
{
namespace cuda
{
namespace
{

using gpu::Index;

constexpr int kThreads = 256;

template <class Kernel>
__global__ void runKernel(Kernel kernel, Index threads)
{
  const Index thread = static_cast<Index>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (thread < threads)
  {
    kernel(thread);
  }
}

/// out[z][x][y] = in[z][y][x] for every slice, through a padded shared-memory tile.
template <class T>
__global__ void transposeSlices(const T* in, T* out, Index nx, Index ny)
{
  __shared__ T tile[32][33];
  const Index z = blockIdx.z;
  const Index x0 = static_cast<Index>(blockIdx.x) * 32, y0 = static_cast<Index>(blockIdx.y) * 32;
  for (int j = threadIdx.y; j < 32; j += blockDim.y)
  {
    const Index x = x0 + threadIdx.x, y = y0 + j;
    if (x < nx && y < ny)
    {
      tile[j][threadIdx.x] = in[(z * ny + y) * nx + x];
    }
  }
  __syncthreads();
  for (int j = threadIdx.y; j < 32; j += blockDim.y)
  {
    const Index y = y0 + threadIdx.x, x = x0 + j;
    if (x < nx && y < ny)
    {
      out[(z * nx + x) * ny + y] = tile[threadIdx.x][j];
    }
  }
}

/// A thread block as FusedStatistics.h's Block: each phase strided over the threads, then
/// a barrier.
struct DeviceBlock
{
  template <class F>
  VAO_HD void each(Index count, F&& f) const
  {
#ifdef __CUDA_ARCH__
    for (Index i = threadIdx.x; i < count; i += blockDim.x)
      f(i);
    __syncthreads();
#else
    for (Index i = 0; i < count; ++i)
      f(i);
#endif
  }
};

template <class Kernel>
__global__ void fusedBlocks(Kernel kernel)
{
  extern __shared__ __align__(16) unsigned char fusedShared[];
  kernel.run(DeviceBlock{}, static_cast<Index>(blockIdx.x),
    reinterpret_cast<typename Kernel::Acc*>(fusedShared));
}

/// Bytes of shared memory a block may have on the current device (the opt-in maximum).
Index sharedMemoryLimit()
{
  int device = 0, bytes = 0;
  check(cudaGetDevice(&device), "device");
  check(cudaDeviceGetAttribute(&bytes, cudaDevAttrMaxSharedMemoryPerBlockOptin, device),
    "device attribute");
  return bytes;
}

/// Launches a FusedBoxSums kernel, one block of 32 x 8 threads per tile and segment, with
/// the shared memory it needs (opted into beyond the default 48 KiB).
template <class Kernel>
void launchFusedBlocks(const Kernel& kernel, cudaStream_t stream)
{
  const Index shared = kernel.sharedBytes();
  if (shared > 48 * 1024)
    check(cudaFuncSetAttribute(fusedBlocks<Kernel>, cudaFuncAttributeMaxDynamicSharedMemorySize,
            static_cast<int>(shared)),
      "shared memory size");
  if (kernel.blocks() > 0)
    fusedBlocks<Kernel><<<static_cast<unsigned>(kernel.blocks()),
      static_cast<unsigned>(gpu::kTileColumns), static_cast<std::size_t>(shared), stream>>>(kernel);
}

/// Runs the pipeline's kernels on the device. When asked for timings, each pass gets a
/// pair of CUDA events; they are read once at the end (finish), so timing adds no waits
/// between passes.
class CudaExecutor
{
public:
  CudaExecutor(Timing* timing, const Execution& execution)
    : Report(timing)
    , Exec(execution)
  {
  }
  ~CudaExecutor()
  {
    for (const Pass& pass : this->Passes)
    {
      if (pass.start)
        cudaEventDestroy(pass.start);
      if (pass.stop)
        cudaEventDestroy(pass.stop);
    }
  }
  CudaExecutor(const CudaExecutor&) = delete;
  CudaExecutor& operator=(const CudaExecutor&) = delete;

  template <class U>
  DeviceBuffer<U> allocate(Index count)
  {
    return DeviceBuffer<U>(count);
  }

  template <class U>
  DeviceBuffer<U> upload(const U* host, Index count)
  {
    DeviceBuffer<U> buffer(count);
    check(cudaMemcpy(buffer.get(), host, count * sizeof(U), cudaMemcpyHostToDevice), "upload");
    return buffer;
  }

  /// Through pinned staging, after the kernels queued so far.
  template <class U>
  void download(U* host, const U* device, Index count)
  {
    stagedDownload(reinterpret_cast<unsigned char*>(host),
      reinterpret_cast<const unsigned char*>(device), count * static_cast<Index>(sizeof(U)),
      this->Exec.threads);
  }

  template <class Kernel>
  void launch(const Kernel& kernel, const char* name, double bytes)
  {
    const Index threads = kernel.threads();
    this->begin();
    if (threads > 0)
    {
      runKernel<<<static_cast<unsigned>((threads + kThreads - 1) / kThreads), kThreads>>>(
        kernel, threads);
    }
    this->end(name, bytes);
  }

  /// A FusedStatistics.h kernel, timed like a pass.
  template <class Kernel>
  void launchBlocks(const Kernel& kernel, const char* name, double bytes)
  {
    this->begin();
    launchFusedBlocks(kernel, nullptr);
    this->end(name, bytes);
  }

  Index sharedLimit() const { return sharedMemoryLimit(); }

  template <class U>
  void transpose(const U* in, U* out, Index nx, Index ny, Index nz, const char* name)
  {
    this->begin();
    const dim3 grid(static_cast<unsigned>((nx + 31) / 32), static_cast<unsigned>((ny + 31) / 32),
      static_cast<unsigned>(nz));
    transposeSlices<U><<<grid, dim3(32, 8)>>>(in, out, nx, ny);
    this->end(name, 2.0 * nx * ny * nz * sizeof(U));
  }

  /// Waits for the launched kernels.
  void synchronize() { check(cudaDeviceSynchronize(), "passes"); }

  /// Between stages only: a running kernel is not interrupted.
  void progress(double fraction)
  {
    if (this->Exec.progress)
      this->Exec.progress(fraction);
    if (this->Exec.abortRequested && this->Exec.abortRequested())
      throw Cancelled{};
  }

  /// Waits for the passes and reports their times.
  void finish()
  {
    check(cudaDeviceSynchronize(), "passes");
    for (const Pass& pass : this->Passes)
    {
      float ms = 0.0f;
      check(cudaEventElapsedTime(&ms, pass.start, pass.stop), "event time");
      this->Report->passes.push_back({ pass.name, ms, pass.bytes });
      this->Report->kernelMilliseconds += ms;
    }
  }

private:
  struct Pass
  {
    const char* name;
    double bytes;
    cudaEvent_t start;
    cudaEvent_t stop;
  };

  void begin()
  {
    if (!this->Report)
      return;
    this->Passes.push_back({ nullptr, 0.0, nullptr, nullptr }); // destroyed with the executor
    Pass& pass = this->Passes.back();
    check(cudaEventCreate(&pass.start), "event");
    check(cudaEventCreate(&pass.stop), "event");
    check(cudaEventRecord(pass.start), "event record");
  }
  /// Ends a pass: checks its launch and records its stop event.
  void end(const char* name, double bytes)
  {
    check(cudaGetLastError(), name);
    if (!this->Report)
      return;
    Pass& pass = this->Passes.back();
    pass.name = name;
    pass.bytes = bytes;
    check(cudaEventRecord(pass.stop), "event record");
  }

  Timing* Report;
  const Execution& Exec;
  std::vector<Pass> Passes;
};

/// Copies the block the region reads into device memory, contiguous.
} // namespace
} // namespace cuda
} // namespace vao
