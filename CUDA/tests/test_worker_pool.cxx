// The one threading primitive (src/cpu/common/Parallel.h): persistent workers, teams, nesting,
// exceptions, and the default thread count.
#include "SweepTestSupport.h"
#include "TestVolumes.h"
#include "cpu/common/Parallel.h"
#include "vao/AmbientOcclusion.h"
#include "vao/BlockSweeping.h"

#include <gtest/gtest.h>

#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <memory>
#include <new>
#include <numeric>
#include <set>
#include <thread>
#include <vector>

namespace
{

using namespace vaotest;
using vao::detail::ChunkProgress;
using vao::detail::parallelFor;
using vao::detail::workerThreadsStarted;

TEST(WorkerPool, EveryIndexOnceAndTheTeamRunsAtTheSameTime)
{
  constexpr int kTeam = 3;
  std::vector<std::atomic<int>> visits(1000);
  std::atomic<int> arrived{ 0 };
  std::set<std::thread::id> ids;
  std::mutex idsMutex;
  parallelFor(static_cast<std::int64_t>(visits.size()), kTeam, kTeam,
    [&](std::int64_t begin, std::int64_t end)
    {
      // Every member waits for the others: this finishes only if all run concurrently,
      // which the sweep's wavefront relies on.
      ++arrived;
      while (arrived.load() < kTeam)
        std::this_thread::yield();
      for (std::int64_t i = begin; i < end; ++i)
        ++visits[i];
      std::lock_guard<std::mutex> lock(idsMutex);
      ids.insert(std::this_thread::get_id());
    });
  for (const auto& v : visits)
    ASSERT_EQ(v.load(), 1);
  EXPECT_EQ(ids.size(), std::size_t(kTeam));
}

TEST(WorkerPool, ANestedLoopRunsInOrderOnItsCaller)
{
  std::vector<std::int64_t> inner(4 * 50, -1);
  parallelFor(4, 4, 2,
    [&](std::int64_t begin, std::int64_t end)
    {
      for (std::int64_t outer = begin; outer < end; ++outer)
      {
        std::int64_t next = 0;
        const std::thread::id caller = std::this_thread::get_id();
        parallelFor(50, 50, 4,
          [&](std::int64_t b, std::int64_t e)
          {
            EXPECT_EQ(std::this_thread::get_id(), caller)
              << "a nested loop must not wait on the busy pool";
            for (std::int64_t i = b; i < e; ++i)
              inner[outer * 50 + i] = next++; // in order: 0, 1, 2, ...
          });
      }
    });
  for (std::int64_t outer = 0; outer < 4; ++outer)
    for (std::int64_t i = 0; i < 50; ++i)
      ASSERT_EQ(inner[outer * 50 + i], i);
}

TEST(WorkerPool, AnExceptionInAChunkReachesTheCallerAndThePoolStaysUsable)
{
  EXPECT_THROW(parallelFor(8, 8, 2,
                 [](std::int64_t begin, std::int64_t)
                 {
                   if (begin == 5)
                     throw std::bad_alloc();
                 }),
    std::bad_alloc);
  std::atomic<std::int64_t> sum{ 0 };
  parallelFor(100, 4, 2,
    [&](std::int64_t begin, std::int64_t end)
    {
      for (std::int64_t i = begin; i < end; ++i)
        sum += i;
    });
  EXPECT_EQ(sum.load(), 4950);
}

TEST(WorkerPool, AChunkThatThrowsStopsTheMembersThatWaitOnIt)
{
  // A wavefront: chunk 1 waits until chunk 0 has done its work or the loop has stopped.
  // Chunk 0 throws instead (as an allocation may), so only the stop lets chunk 1 return.
  // (Chunk 1 may also never start, when the stop comes first.)
  std::atomic<bool> oneTimedOut{ false };
  EXPECT_THROW(parallelFor(2, 2, 2, vao::Execution{},
                 [&](std::int64_t begin, std::int64_t, ChunkProgress& progress)
                 {
                   if (begin == 0)
                     throw std::bad_alloc();
                   const auto start = std::chrono::steady_clock::now();
                   while (!progress.stopped())
                   {
                     // A bound, so that the test fails instead of hanging.
                     if (std::chrono::steady_clock::now() - start > std::chrono::seconds(20))
                     {
                       oneTimedOut = true;
                       return;
                     }
                     std::this_thread::yield();
                   }
                 }),
    std::bad_alloc);
  EXPECT_FALSE(oneTimedOut.load());
}

TEST(WorkerPool, CancellationStopsTheLoop)
{
  vao::Execution execution;
  int polls = 0;
  execution.abortRequested = [&] { return ++polls >= 3; };
  std::atomic<int> done{ 0 };
  const bool finished = parallelFor(1000, 1000, 2, execution,
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress)
    {
      for (std::int64_t i = begin; i < end && progress.advance(); ++i)
        ++done;
    });
  EXPECT_FALSE(finished);
  EXPECT_LT(done.load(), 1000);
}

TEST(WorkerPool, OneAmbientOcclusionRunStartsAtMostTheWorkersOfItsTeam)
{
  constexpr int kThreads = 3;
  const vao::Index3 dims = { 24, 20, 30 };
  const std::vector<float> values = randomVolume<float>(dims, -5.0, 5.0, 7);
  std::vector<float> open(static_cast<std::size_t>(dims[0] * dims[1] * dims[2]));
  vao::AmbientOcclusionParameters p;
  p.method = vao::Method::CdfReconstruction; // bands x (extrema passes + moments): many loops
  p.radius = { 2, 2, 2 };
  vao::Execution execution;
  execution.threads = kThreads;
  const std::int64_t before = workerThreadsStarted();
  for (int run = 0; run < 3; ++run)
  {
    ASSERT_TRUE(vao::computeAmbientOcclusion(viewOf(values, dims),
      vao::Region::whole(viewOf(values, dims)), p, { open.data(), nullptr }, execution)
                  .ok);
  }
  EXPECT_LE(workerThreadsStarted() - before, kThreads - 1);
}

TEST(WorkerPool, FourBlockSweepingRoundsStartAtMostTheWorkersOfOneTeam)
{
  // Four z-slabs as four ranks would hold them, swept round after round with their faces
  // exchanged: 8 sweeps x passes x rounds x blocks loops, and still no new threads.
  constexpr int kThreads = 3;
  const Scene scene = makeScene({ 20, 20, 40 }, { 1, 1, 1 }, sphere(10, 10, 20, 6));
  vao::SweepParameters p = withIterations(2, 1e-6);
  vao::Execution execution;
  execution.threads = kThreads;
  std::vector<std::vector<float>> scalars(4);
  std::vector<std::unique_ptr<vao::BlockSweeper>> blocks;
  for (int b = 0; b < 4; ++b)
  {
    vao::BlockPlacement placement;
    placement.whole = scene.dims;
    placement.begin = { 0, 0, 10 * b };
    placement.size = { 20, 20, 10 };
    const std::int64_t z0 = placement.begin[2] - placement.hasNeighbour(4);
    const std::int64_t z1 = placement.begin[2] + placement.size[2] + placement.hasNeighbour(5);
    scalars[b].assign(scene.values.begin() + z0 * 400, scene.values.begin() + z1 * 400);
    blocks.push_back(std::make_unique<vao::BlockSweeper>(
      viewOf(scalars[b], placement.scalarDims()), placement, scene.spacing, p, execution));
    ASSERT_TRUE(blocks.back()->initialise().ok);
  }
  const std::int64_t before = workerThreadsStarted();
  for (int round = 0; round < 6; ++round)
  {
    std::vector<std::vector<float>> up(4), down(4);
    for (int b = 0; b < 4; ++b)
    {
      ASSERT_TRUE(blocks[b]->runRound(p.iterations).ok);
      up[b].resize(static_cast<std::size_t>(blocks[b]->faceValueCount(5)));
      down[b].resize(static_cast<std::size_t>(blocks[b]->faceValueCount(4)));
      blocks[b]->exportFace(5, up[b].data());
      blocks[b]->exportFace(4, down[b].data());
    }
    for (int b = 0; b < 4; ++b)
    {
      if (b > 0)
        blocks[b]->importFace(4, up[b - 1].data());
      if (b < 3)
        blocks[b]->importFace(5, down[b + 1].data());
    }
  }
  EXPECT_LE(workerThreadsStarted() - before, kThreads - 1);
}

TEST(WorkerPool, AForkedChildRunsItsLoopsWithoutItsParentsWorkers)
{
  // Python's multiprocessing forks pvpython: the child has none of the parent's threads,
  // so waiting on the parent's workers would hang it.
  parallelFor(8, 8, 3, [](std::int64_t, std::int64_t) {}); // the parent has workers
  const pid_t child = fork();
  ASSERT_GE(child, 0);
  if (child == 0)
  {
    alarm(20); // a hang ends the child with SIGALRM instead of the test run
    std::atomic<std::int64_t> sum{ 0 };
    parallelFor(100, 4, 3,
      [&](std::int64_t begin, std::int64_t end)
      {
        for (std::int64_t i = begin; i < end; ++i)
          sum += i;
      });
    _exit(sum.load() == 4950 ? 0 : 1);
  }
  int status = 0;
  ASSERT_EQ(waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0)
    << "the child's loop hung or went wrong";
}

TEST(WorkerPool, DefaultThreadsDivideTheNodeByItsRanks)
{
  using vao::detail::defaultThreadCount;
  EXPECT_EQ(defaultThreadCount(16, false, 1), 16);
  EXPECT_EQ(defaultThreadCount(16, false, 4), 4);
  EXPECT_EQ(defaultThreadCount(2, false, 4), 1) << "never below one thread";
  EXPECT_EQ(defaultThreadCount(3, true, 4), 3)
    << "a launcher that bound the process has divided already";
  EXPECT_EQ(vao::detail::resolveThreadCount(5), 5) << "an explicit count wins";
}

} // namespace
