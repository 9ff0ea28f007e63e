// The sweeps of occlusion sweeping: the Godunov update of the signed distance (Eq. 1) with
// the octant visibility of Eq. 6 carried along (the rows: SweepRows.h), plane by plane,
// and the passes of 8 sweeps.
//
// A sweep visits z-planes, rows and voxels in its direction; every value it needs from
// upwind is in the previous voxel (kept in registers), the previous row, or the previous
// plane. The result of a sweep does not depend on the visiting order as long as every voxel
// comes after its upwind neighbours, so planes run as a wavefront on the members of one
// parallelFor team: plane k may start row j once plane k-1 has finished row j. Each
// member sweeps two planes at a time, the second a row behind, their rows interleaved.
#include "cpu/occlusion_sweeping/SweepRows.h"
#include "cpu/occlusion_sweeping/SweepingCore.h"

#include "cpu/common/Parallel.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <thread>
#include <vector>

namespace vao
{
namespace detail
{
namespace sweeping
{
namespace
{

static_assert(
  kPlanesTogether >= 1 && kPlanesTogether <= 2, "sweepRows takes one or two rows at a time");

struct alignas(64) RowCounter
{
  std::atomic<std::int64_t> done{ 0 };
};

class Sweeper
{
public:
  Sweeper(const SweepLayout& layout, const SweepConstants& constants, float* distance,
    const FixedMask& fixed, VisibilityStore& visibility, int threads)
    : Layout(layout)
    , Storage(layout.storage)
    , Constants(constants)
    , Distance(distance)
    , Fixed(fixed.words())
    , Visibility(visibility)
    , Threads(threads)
    , SkyDistance(layout.size[0], kInfinity)
    , SkyVisibility(layout.size[0], 1.0f)
  {
  }

  /// The sweep of `octant` over the own voxels. Returns false when cancelled.
  bool sweep(int octant, bool visibility, const Execution& execution, RowResult& total)
  {
    const std::int64_t planes = this->Layout.size[2];
    SweepState state(octant, visibility, planes);
    // Pairs of planes per chunk: member t sweeps pairs t, t + T, ... (the wavefront,
    // Parallel.h), each pair's two planes together (sweepPlanes).
    const std::int64_t chunks = (planes + kPlanesTogether - 1) / kPlanesTogether;
    const bool finished =
      detail::parallelFor(planes, static_cast<int>(chunks), this->Threads, execution,
        [&](std::int64_t k0, std::int64_t k1, detail::ChunkProgress& progress)
        {
          std::vector<float> scratch(
            static_cast<std::size_t>(kPlanesTogether * this->scratchPerRow()));
          for (std::int64_t k = k0; k < k1 && !progress.stopped(); k += kPlanesTogether)
          {
            const int count = static_cast<int>(std::min<std::int64_t>(kPlanesTogether, k1 - k));
            if (!this->sweepPlanes(state, k, count, scratch.data(), progress))
            {
              return;
            }
            progress.advance(count);
          }
        });
    for (const RowResult& r : state.planeResults)
    {
      total.largestChange = std::max(total.largestChange, r.largestChange);
      total.reachedNew = total.reachedNew || r.reachedNew;
    }
    return finished;
  }

private:
  struct SweepState
  {
    int octant;
    std::array<int, 3> dir;
    bool visibility;
    RowFunction rowKernel;
    std::vector<RowCounter> rowsDone;    // per plane k (in sweep order): rows finished
    std::vector<RowResult> planeResults; // per plane k

    SweepState(int octant, bool withVisibility, std::int64_t planes)
      : octant(octant)
      , dir(sweepDirection(octant))
      , visibility(withVisibility)
      , rowKernel(rowFunction(dir[0], withVisibility))
      , rowsDone(static_cast<std::size_t>(planes))
      , planeResults(static_cast<std::size_t>(planes))
    {
    }
  };

  /// Planes k and k + 1 (count 2) or plane k alone (count 1) of the sweep (k counts in
  /// sweep order). Row j of plane k waits for plane k - 1's; plane k + 1 follows one row
  /// behind plane k, so the two rows of a step are independent and run interleaved.
  bool sweepPlanes(SweepState& state, std::int64_t k, int count, float* scratch,
    const detail::ChunkProgress& progress)
  {
    const std::int64_t rows = this->Layout.size[1];
    for (std::int64_t step = 0; step < rows + count - 1; ++step)
    {
      if (step < rows && k > 0 && !waitForRow(state.rowsDone[k - 1], step, progress))
      {
        return false;
      }
      // (plane, row) of this step's rows: plane k's row `step`, plane k + 1's the one before.
      std::int64_t plane[kPlanesTogether], row[kPlanesTogether];
      int n = 0;
      for (int p = 0; p < count; ++p)
      {
        if (step - p >= 0 && step - p < rows)
        {
          plane[n] = k + p;
          row[n] = step - p;
          ++n;
        }
      }
      RowView views[kPlanesTogether];
      RowResult results[kPlanesTogether];
      for (int r = 0; r < n; ++r)
        views[r] = this->rowView(state, plane[r], row[r], scratch + r * this->scratchPerRow());
      state.rowKernel(views, n, this->Layout.size[0], this->Constants, results);
      for (int r = 0; r < n; ++r)
        this->finishRow(state, plane[r], row[r], results[r]);
    }
    return true;
  }

  /// Row j of plane k is done: its changes, its octant's share of the sum, and the
  /// wavefront's count.
  void finishRow(SweepState& state, std::int64_t k, std::int64_t j, const RowResult& r)
  {
    RowResult& result = state.planeResults[k];
    result.largestChange = std::max(result.largestChange, r.largestChange);
    result.reachedNew = result.reachedNew || r.reachedNew;
    if (state.visibility && !this->Visibility.kept)
    {
      const Grid& g = this->Storage;
      const std::int64_t y = this->storageY(state, j), z = this->storageZ(state, k);
      float* sum = this->Visibility.sum + g.index(this->Layout.offset[0], y, z);
      const float* v = this->Visibility.row(state.octant, y, z, g) + this->Layout.offset[0];
      for (std::int64_t x = 0; x < this->Layout.size[0]; ++x)
      {
        sum[x] += v[x];
      }
    }
    state.rowsDone[k].done.store(j + 1, std::memory_order_release);
  }

  /// A row's scratch for its upwind terms (RowView::scratch).
  std::int64_t scratchPerRow() const { return UpwindTerms::kRows * this->Layout.size[0]; }

  std::int64_t storageY(const SweepState& state, std::int64_t j) const
  {
    return this->Layout.offset[1] + (state.dir[1] > 0 ? j : this->Layout.size[1] - 1 - j);
  }
  std::int64_t storageZ(const SweepState& state, std::int64_t k) const
  {
    return this->Layout.offset[2] + (state.dir[2] > 0 ? k : this->Layout.size[2] - 1 - k);
  }

  /// Row j of plane k (in sweep order) with its upwind row and plane, or the open sky where
  /// they are outside; the x-upwind neighbour of its first voxel likewise (from storage when
  /// the layout is ghosted).
  RowView rowView(const SweepState& state, std::int64_t k, std::int64_t j, float* scratch)
  {
    const Grid& g = this->Storage;
    const std::int64_t y = this->storageY(state, j), z = this->storageZ(state, k);
    const bool hasUpwindRow = this->Layout.ghosted || j > 0,
               hasUpwindPlane = this->Layout.ghosted || k > 0;
    const std::int64_t sky0 = state.dir[0] > 0 ? 0 : this->Layout.size[0] - 1; // in the sky rows
    const std::int64_t x0 = this->Layout.offset[0] + sky0;
    const std::int64_t rowStep = state.dir[1] * g.nx, planeStep = state.dir[2] * g.plane;
    const std::int64_t i = g.index(x0, y, z);
    const bool ghosted = this->Layout.ghosted;
    RowView row{ this->Distance + i,
      hasUpwindRow ? this->Distance + i - rowStep : this->SkyDistance.data() + sky0,
      hasUpwindPlane ? this->Distance + i - planeStep : this->SkyDistance.data() + sky0,
      this->Fixed, i, nullptr, nullptr, nullptr,
      ghosted ? this->Distance[i - state.dir[0]] : kInfinity, 1.0f, scratch };
    if (state.visibility)
    {
      VisibilityStore& vis = this->Visibility;
      row.v = vis.row(state.octant, y, z, g) + x0;
      row.vy =
        hasUpwindRow ? row.v - state.dir[1] * vis.pitch(g) : this->SkyVisibility.data() + sky0;
      row.vz = hasUpwindPlane ? vis.row(state.octant, y, z - state.dir[2], g) + x0
                              : this->SkyVisibility.data() + sky0;
      row.startV = ghosted ? row.v[-state.dir[0]] : 1.0f;
    }
    return row;
  }

  /// Spins until the upwind plane has finished row j: rows take microseconds, less than a
  /// sleep would cost.
  static bool waitForRow(
    const RowCounter& upwindPlane, std::int64_t j, const detail::ChunkProgress& progress)
  {
    while (upwindPlane.done.load(std::memory_order_acquire) <= j)
    {
      if (progress.stopped())
      {
        return false;
      }
      std::this_thread::yield();
    }
    return true;
  }

  const SweepLayout& Layout;
  const Grid& Storage;
  const SweepConstants& Constants;
  float* Distance;
  const std::uint64_t* Fixed; // FixedMask words
  VisibilityStore& Visibility;
  int Threads;
  std::vector<float> SkyDistance;   // a row of open sky: D = +inf
  std::vector<float> SkyVisibility; // and V = 1
};
} // namespace

Status runPasses(const SweepLayout& layout, const SweepParameters& p, float* distance,
  const FixedMask& fixed, VisibilityStore& vis, int threads, const Execution& execution,
  SweepReport& report)
{
  const SweepConstants constants(layout.storage.h, p.opacity);
  Sweeper sweeper(layout, constants, distance, fixed, vis, threads);
  for (int pass = 0; pass < p.iterations; ++pass)
  {
    if (vis.sum)
    {
      // V is recomputed in every pass. The workers zero it: in the first pass this is the
      // output's first touch.
      detail::parallelFor(layout.storage.count, 4 * threads, threads,
        [&](std::int64_t begin, std::int64_t end)
        { std::fill(vis.sum + begin, vis.sum + end, 0.0f); });
    }
    RowResult total;
    for (int s = 0; s < 8; ++s)
    {
      const double step = 1.0 / (8.0 * p.iterations);
      const Execution stage =
        detail::stageExecution(execution, (pass * 8 + s) * step, (pass * 8 + s + 1) * step);
      if (!sweeper.sweep(s, vis.computed[s], stage, total))
      {
        return Status::cancelled();
      }
    }
    report.passes = pass + 1;
    report.lastChange = total.largestChange;
    if (p.tolerance > 0.0 && !total.reachedNew && total.largestChange < p.tolerance)
    {
      break;
    }
  }
  return Status::success();
}
} // namespace sweeping
} // namespace detail
} // namespace vao
