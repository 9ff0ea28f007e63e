// Device errors as exceptions, and device allocations freed on every exit path (only the
// CUDA backend's headers include it).
#pragma once

#include "cuda/common/Pipeline.h"

#include <cuda_runtime.h>

#include <stdexcept>
#include <string>

namespace vao
{
namespace cuda
{
namespace
{

using gpu::Index;

struct CudaFailure : std::runtime_error
{
  using std::runtime_error::runtime_error;
};

/// The user aborted between two stages: unwinds like a failure, reported as cancelled.
struct Cancelled
{
};

void check(cudaError_t error, const char* what)
{
  if (error != cudaSuccess)
  {
    throw CudaFailure(std::string("CUDA ") + what + ": " + cudaGetErrorString(error));
  }
}

/// A device allocation, freed on every exit path.
template <class T>
class DeviceBuffer
{
public:
  explicit DeviceBuffer(Index count)
  {
    if (count > 0)
    {
      check(cudaMalloc(&this->Data, static_cast<size_t>(count) * sizeof(T)), "allocation");
    }
  }
  ~DeviceBuffer() { cudaFree(this->Data); }
  DeviceBuffer(DeviceBuffer&& other) noexcept
    : Data(other.Data)
  {
    other.Data = nullptr;
  }
  DeviceBuffer& operator=(DeviceBuffer&& other) noexcept
  {
    if (this != &other)
    {
      cudaFree(this->Data);
      this->Data = other.Data;
      other.Data = nullptr;
    }
    return *this;
  }
  DeviceBuffer(const DeviceBuffer&) = delete;
  DeviceBuffer& operator=(const DeviceBuffer&) = delete;
  T* get() const { return this->Data; }

private:
  T* Data = nullptr;
};

} // namespace
} // namespace cuda
} // namespace vao
