#include "Parallel.h"

#include <algorithm>
#include <thread>
#include <vector>

namespace vao
{
namespace detail
{

int resolveThreadCount(int requested)
{
  if (requested > 0)
  {
    return requested;
  }
  const unsigned hardware = std::thread::hardware_concurrency();
  return hardware > 0 ? static_cast<int>(hardware) : 1;
}

Execution stageExecution(const Execution& execution, double from, double to)
{
  Execution stage = execution;
  if (execution.progress)
  {
    const auto report = execution.progress;
    stage.progress = [report, from, to](double p) { report(from + (to - from) * p); };
  }
  return stage;
}

LoopControl::LoopControl(const Execution& execution, std::int64_t totalWork)
  : Exec(execution)
  , Total(std::max<std::int64_t>(totalWork, 1))
{
}

bool LoopControl::advance(std::int64_t work, bool onCallingThread)
{
  const std::int64_t done = this->Done.fetch_add(work, std::memory_order_relaxed) + work;
  if (onCallingThread)
  {
    if (this->Exec.progress)
    {
      this->Exec.progress(std::min(1.0, static_cast<double>(done) / this->Total));
    }
    if (this->Exec.abortRequested && this->Exec.abortRequested())
    {
      this->Stop.store(true, std::memory_order_relaxed);
    }
  }
  return !this->stopped();
}

void parallelChunks(std::int64_t n, int chunks,
  const std::function<void(std::int64_t, std::int64_t, bool)>& body, int threads)
{
  chunks = static_cast<int>(std::max<std::int64_t>(1, std::min<std::int64_t>(chunks, n)));
  if (n <= 0)
  {
    return;
  }
  auto chunkRange = [n, chunks](int c) {
    return std::make_pair(n * c / chunks, n * (c + 1) / chunks);
  };
  threads = std::max(1, std::min(threads, chunks));
  // Chunk c goes to thread c % threads; the caller (thread 0) takes its share too.
  auto runThread = [&](int t) {
    for (int c = t; c < chunks; c += threads)
    {
      const auto range = chunkRange(c);
      body(range.first, range.second, t == 0);
    }
  };
  std::vector<std::thread> workers;
  workers.reserve(threads - 1);
  for (int t = 1; t < threads; ++t)
  {
    workers.emplace_back(runThread, t);
  }
  runThread(0);
  for (auto& worker : workers)
  {
    worker.join();
  }
}

} // namespace detail
} // namespace vao
