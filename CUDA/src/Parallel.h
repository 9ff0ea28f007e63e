// A minimal fork-join loop for the CPU path (the kernel library has no VTK, so no
// vtkSMPTools): chunks of [0, n) run on worker threads and on the caller, and only the
// caller reports progress and polls for cancellation, so those callbacks may be unsafe
// to call from other threads (VTK's UpdateProgress, GetAbortExecute).
#pragma once

#include "vao/AmbientOcclusion.h"

#include <atomic>
#include <cstdint>
#include <functional>

namespace vao
{
namespace detail
{

int resolveThreadCount(int requested);

/// The same execution with progress mapped into [from, to] of the caller's range, for one
/// stage of a multi-stage computation.
Execution stageExecution(const Execution& execution, double from, double to);

/// Shared by the chunks of one loop: how far it is and whether it must stop.
class LoopControl
{
public:
  LoopControl(const Execution& execution, std::int64_t totalWork);

  /// Called by any thread after finishing `work` units; returns false to stop.
  bool advance(std::int64_t work, bool onCallingThread);
  bool stopped() const { return this->Stop.load(std::memory_order_relaxed); }

private:
  const Execution& Exec;
  std::int64_t Total;
  std::atomic<std::int64_t> Done{ 0 };
  std::atomic<bool> Stop{ false };
};

/// Runs body(chunkBegin, chunkEnd, onCallingThread) over `chunks` equal chunks of [0, n).
void parallelChunks(std::int64_t n, int chunks,
  const std::function<void(std::int64_t, std::int64_t, bool)>& body, int threads);

} // namespace detail
} // namespace vao
