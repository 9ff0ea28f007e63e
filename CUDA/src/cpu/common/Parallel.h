// The one threading primitive of the CPU path: parallelFor over a persistent worker pool.
//
// The kernel library has no VTK (so no vtkSMPTools) and must not depend on which SMP
// backend a VTK build chose. Threads are started once per process and reused: a filter
// run makes dozens of passes and the distributed sweep hundreds of rounds, and starting
// a thread set per pass would cost more than a small pass itself.
//
// A loop's chunks run as a team: member 0 is the calling thread, the others are pool
// workers that run nothing else meanwhile, so all members run at the same time. The
// wavefront of the occlusion sweeps relies on that (a plane waits, spinning, for its
// upwind plane on another member), which is why this is a team pool and not a task queue
// such as oneTBB's, where a waiting task may hold the only thread its upwind task needs.
// A call made while the pool is busy (nested, or from another thread) runs as a team of
// one: its chunks run in order on the caller, which keeps any wavefront valid.
//
// Only the calling thread reports progress and polls for cancellation, so those callbacks
// may be unsafe to call from other threads (VTK's UpdateProgress, GetAbortExecute).
#pragma once

#include "vao/AmbientOcclusion.h"

#include <atomic>
#include <cstdint>
#include <functional>

namespace vao
{
namespace detail
{

/// This process's rank among the job's ranks on its node, as the MPI launchers announce it
/// (OMPI_COMM_WORLD_LOCAL_RANK, MPI_LOCALRANKID, MV2_COMM_WORLD_LOCAL_RANK, SLURM_LOCALID),
/// 0 without one.
int nodeLocalRank();

/// Threads a computation uses when the caller asks for `requested` (0: the default).
/// The default is the cores this process may run on; when the process may run on every
/// core of the node and a launcher says several ranks share the node
/// (OMPI_COMM_WORLD_LOCAL_SIZE, MPI_LOCALNRANKS, MV2_COMM_WORLD_LOCAL_SIZE), those cores
/// divided by the ranks, at least 1.
int resolveThreadCount(int requested);

/// The default for a process that may run on `availableCores` cores (`restricted`: fewer
/// than the machine has, so a launcher bound it) with `ranksOnNode` ranks on its node.
int defaultThreadCount(int availableCores, bool restricted, int ranksOnNode);

/// Worker threads the pool has started since the process began (for tests: it is bounded
/// by the largest team asked for, not by the number of loops run).
std::int64_t workerThreadsStarted();

/// The same execution with progress mapped into [from, to] of the caller's range, for one
/// stage of a multi-stage computation.
Execution stageExecution(const Execution& execution, double from, double to);

/// The stage of a pyramid of `levels` levels that builds levels `first` to `last`, each
/// level an eighth of the one before it: its share of the progress is its share of the
/// work, so that the coarse levels do not take most of the bar while costing little.
Execution pyramidStageExecution(const Execution& execution, int first, int last, int levels);

/// Shared by the chunks of one loop: how far it is and whether it must stop.
class LoopControl
{
public:
  LoopControl(const Execution& execution, std::int64_t totalWork);

  /// Called by any thread after finishing `work` units; returns false to stop.
  bool advance(std::int64_t work, bool onCallingThread);
  bool stopped() const { return this->Stop.load(std::memory_order_relaxed); }
  /// Stops the loop: the other members' ChunkProgress::stopped() turns true.
  void stop() { this->Stop.store(true, std::memory_order_relaxed); }

private:
  const Execution& Exec;
  std::int64_t Total;
  std::atomic<std::int64_t> Done{ 0 };
  std::atomic<bool> Stop{ false };
};

/// What one chunk of a parallelFor sees: report finished work, learn whether to stop.
class ChunkProgress
{
public:
  ChunkProgress(LoopControl& control, bool onCallingThread)
    : Control(control)
    , OnCallingThread(onCallingThread)
  {
  }
  /// `work` more units are done; false: the loop was cancelled, return soon.
  bool advance(std::int64_t work = 1) { return this->Control.advance(work, this->OnCallingThread); }
  bool stopped() const { return this->Control.stopped(); }

private:
  LoopControl& Control;
  bool OnCallingThread;
};

using ChunkBody =
  std::function<void(std::int64_t begin, std::int64_t end, ChunkProgress& progress)>;

/// Runs body over `chunks` equal chunks of [0, n) with up to `threads` threads (0: the
/// default; chunk c goes to team member c mod team, in increasing order). Progress is the
/// work the chunks report out of `totalWork` (-1: n). An exception thrown by a chunk (say,
/// std::bad_alloc) stops the loop, so that members waiting on that chunk's work (a
/// wavefront) see stopped() instead of waiting for ever, and is rethrown on the caller
/// after every member has finished. Returns false when the execution asked to abort.
bool parallelFor(std::int64_t n, int chunks, int threads, const Execution& execution,
  const ChunkBody& body, std::int64_t totalWork = -1);

/// parallelFor without progress or cancellation.
inline void parallelFor(std::int64_t n, int chunks, int threads,
  const std::function<void(std::int64_t begin, std::int64_t end)>& body)
{
  parallelFor(n, chunks, threads, Execution{},
    [&body](std::int64_t begin, std::int64_t end, ChunkProgress&) { body(begin, end); });
}

} // namespace detail
} // namespace vao
