#include "cpu/common/Parallel.h"

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <cstdlib>
#include <exception>
#include <initializer_list>
#include <mutex>
#include <system_error>
#include <thread>
#include <vector>

#if defined(__linux__)
#include <sched.h>
#endif
#if defined(_WIN32)
#include <process.h>
#else
#include <unistd.h>
#endif

namespace vao
{
namespace detail
{
namespace
{

std::atomic<std::int64_t> startedWorkers{ 0 };

long processId()
{
#if defined(_WIN32)
  return _getpid();
#else
  return static_cast<long>(getpid());
#endif
}

/// Cores this process may run on: its affinity mask where the system has one.
int availableCores(bool& restricted)
{
  const unsigned hardware = std::max(1u, std::thread::hardware_concurrency());
  restricted = false;
#if defined(__linux__)
  cpu_set_t set;
  CPU_ZERO(&set);
  if (sched_getaffinity(0, sizeof(set), &set) == 0)
  {
    const int allowed = CPU_COUNT(&set);
    if (allowed > 0)
    {
      restricted = static_cast<unsigned>(allowed) < hardware;
      return allowed;
    }
  }
#endif
  return static_cast<int>(hardware);
}

/// The first of the launcher's variables `names` that holds a number >= `least`, capped at
/// 2^20, or `fallback`.
int launcherNumber(std::initializer_list<const char*> names, int least, int fallback)
{
  for (const char* name : names)
  {
    if (const char* value = std::getenv(name))
    {
      char* end = nullptr;
      const long number = std::strtol(value, &end, 10);
      if (end != value && number >= least)
      {
        return static_cast<int>(std::min<long>(number, 1 << 20));
      }
    }
  }
  return fallback;
}

/// Ranks of this job on this node, as the MPI launchers announce it (1 without one).
int ranksOnNode()
{
  return launcherNumber(
    { "OMPI_COMM_WORLD_LOCAL_SIZE", "MPI_LOCALNRANKS", "MV2_COMM_WORLD_LOCAL_SIZE" }, 1, 1);
}

/// Persistent workers that run one team job at a time (see Parallel.h).
class WorkerPool
{
public:
  using Task = std::function<void(int member, int team)>;

  /// Never destroyed: its workers wait on a condition variable and end with the process,
  /// so no static destructor can join them while another static still uses the pool.
  static WorkerPool& shared()
  {
    static WorkerPool* pool = new WorkerPool;
    return *pool;
  }

  /// task(member, team) for every member of a team of up to `wanted` threads, the caller
  /// being member 0; a busy pool gives a team of one. Once its own part is done, the
  /// caller calls `waiting` every few milliseconds until the other members finish.
  void run(int wanted, const Task& task, const std::function<void()>& waiting)
  {
    bool idle = false;
    // A forked child (Python's multiprocessing, say) has none of its parent's workers.
    if (wanted <= 1 || processId() != this->Owner ||
      !this->Busy.compare_exchange_strong(idle, true))
    {
      task(0, 1);
      return;
    }
    struct Release
    {
      std::atomic<bool>& busy;
      ~Release() { busy.store(false); }
    } release{ this->Busy };

    const int team = this->grow(wanted);
    {
      std::lock_guard<std::mutex> lock(this->Mutex);
      this->Job = &task;
      this->Team = team;
      this->Pending = team - 1;
      this->Failure = nullptr;
      ++this->Generation;
    }
    this->Wake.notify_all();
    std::exception_ptr failure;
    try
    {
      task(0, team);
    }
    catch (...)
    {
      failure = std::current_exception();
    }
    std::unique_lock<std::mutex> lock(this->Mutex);
    while (!this->Finished.wait_for(
      lock, std::chrono::milliseconds(5), [this] { return this->Pending == 0; }))
    {
      lock.unlock();
      try
      {
        waiting();
      }
      catch (...)
      {
        // The members still use `task`: the caller waits for them before it rethrows.
        failure = failure ? failure : std::current_exception();
      }
      lock.lock();
    }
    this->Job = nullptr;
    if (!failure)
    {
      failure = this->Failure;
    }
    lock.unlock();
    if (failure)
    {
      std::rethrow_exception(failure);
    }
  }

private:
  /// Starts workers until the team can have `wanted` members (or as many as start).
  int grow(int wanted)
  {
    while (static_cast<int>(this->Workers.size()) + 1 < wanted)
    {
      const int member = static_cast<int>(this->Workers.size()) + 1;
      try
      {
        this->Workers.emplace_back([this, member] { this->work(member); });
      }
      catch (const std::system_error&)
      {
        break; // no more threads to be had: a smaller team
      }
      ++startedWorkers;
    }
    return std::min(wanted, static_cast<int>(this->Workers.size()) + 1);
  }

  void work(int member)
  {
    std::uint64_t seen = 0;
    std::unique_lock<std::mutex> lock(this->Mutex);
    for (;;)
    {
      this->Wake.wait(lock, [&] { return this->Generation != seen; });
      seen = this->Generation;
      if (member >= this->Team)
      {
        continue;
      }
      const Task* task = this->Job;
      const int team = this->Team;
      lock.unlock();
      std::exception_ptr failure;
      try
      {
        (*task)(member, team);
      }
      catch (...)
      {
        failure = std::current_exception();
      }
      lock.lock();
      if (failure && !this->Failure)
      {
        this->Failure = failure;
      }
      if (--this->Pending == 0)
      {
        this->Finished.notify_one();
      }
    }
  }

  const long Owner = processId(); // the process whose workers these are
  std::atomic<bool> Busy{ false };
  std::mutex Mutex;
  std::condition_variable Wake;
  std::condition_variable Finished;
  std::vector<std::thread> Workers; // member m is Workers[m - 1]
  const Task* Job = nullptr;
  int Team = 0;
  int Pending = 0;
  std::uint64_t Generation = 0;
  std::exception_ptr Failure;
};

} // namespace

int nodeLocalRank()
{
  return launcherNumber({ "OMPI_COMM_WORLD_LOCAL_RANK", "MPI_LOCALRANKID",
                          "MV2_COMM_WORLD_LOCAL_RANK", "SLURM_LOCALID" },
    0, 0);
}

int resolveThreadCount(int requested)
{
  if (requested > 0)
  {
    return requested;
  }
  static const int fallback = []
  {
    bool restricted = false;
    const int cores = availableCores(restricted);
    return defaultThreadCount(cores, restricted, ranksOnNode());
  }();
  return fallback;
}

int defaultThreadCount(int cores, bool restricted, int ranks)
{
  // A launcher that bound this process to fewer cores has already divided them.
  return restricted ? std::max(1, cores) : std::max(1, cores / std::max(1, ranks));
}

std::int64_t workerThreadsStarted()
{
  return startedWorkers.load();
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

Execution pyramidStageExecution(const Execution& execution, int first, int last, int levels)
{
  double before = 0.0, within = 0.0, total = 0.0, weight = 1.0;
  for (int l = 0; l < levels; ++l, weight /= 8.0)
  {
    total += weight;
    if (l < first)
      before += weight;
    else if (l <= last)
      within += weight;
  }
  return stageExecution(execution, before / total, (before + within) / total);
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
      this->stop();
    }
  }
  return !this->stopped();
}

bool parallelFor(std::int64_t n, int chunks, int threads, const Execution& execution,
  const ChunkBody& body, std::int64_t totalWork)
{
  LoopControl control(execution, totalWork < 0 ? n : totalWork);
  if (n <= 0)
  {
    return true;
  }
  chunks = static_cast<int>(std::max<std::int64_t>(1, std::min<std::int64_t>(chunks, n)));
  const int wanted = std::max(1, std::min(resolveThreadCount(threads), chunks));
  WorkerPool::shared().run(
    wanted,
    [&](int member, int team)
    {
      ChunkProgress progress(control, member == 0);
      try
      {
        for (int c = member; c < chunks && !control.stopped(); c += team)
        {
          body(n * c / chunks, n * (c + 1) / chunks, progress);
        }
      }
      catch (...)
      {
        control.stop();
        throw;
      }
    },
    // The other members' work still moves the progress, and an abort still stops them.
    [&control] { control.advance(0, true); });
  return !control.stopped();
}

} // namespace detail

int threadCount(int requested)
{
  return detail::resolveThreadCount(requested);
}

bool parallelRanges(std::int64_t n, const Execution& execution,
  const std::function<void(std::int64_t begin, std::int64_t end)>& body)
{
  const int threads = detail::resolveThreadCount(execution.threads);
  // Enough chunks for progress to move in steps under 5% (the caller reports the team's
  // work after each of its chunks) and for uneven chunks to even out.
  const std::int64_t chunks = std::max<std::int64_t>(1, std::min<std::int64_t>(n, 32 * threads));
  return detail::parallelFor(n, static_cast<int>(chunks), threads, execution,
    [&](std::int64_t begin, std::int64_t end, detail::ChunkProgress& progress)
    {
      body(begin, end);
      progress.advance(end - begin);
    });
}

} // namespace vao
