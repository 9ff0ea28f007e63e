// The sweeps of occlusion sweeping: the Godunov update of the signed distance (Eq. 1) with
// the octant visibility of Eq. 6 carried along, row by row, and the passes of 8 sweeps.
//
// A sweep visits z-planes, rows and voxels in its direction; every value it needs from
// upwind is in the previous voxel (kept in registers), the previous row, or the previous
// plane. The result of a sweep does not depend on the visiting order as long as every voxel
// comes after its upwind neighbours, so planes run as a wavefront on the members of one
// parallelFor team: plane k may start row j once plane k-1 has finished row j.
#include "SweepingCore.h"

#include "Parallel.h"

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

constexpr float kInfinity = std::numeric_limits<float>::infinity();

struct SweepConstants
{
  float h[3];       // spacing
  float w[3];       // 1 / h^2
  float lowerBound; // no update lands closer than 1/sqrt(w0 + w1 + w2) to the nearest neighbour
  float invTauH;    // 1 / smallest spacing (Eq. 7)
  float alphaThird; // opacity (Eq. 8) / 3
  float thirdClear; // (1 - opacity) / 3

  SweepConstants(const std::array<double, 3>& spacing, double opacity)
  {
    for (int a = 0; a < 3; ++a)
    {
      h[a] = static_cast<float>(spacing[a]);
      w[a] = static_cast<float>(1.0 / (spacing[a] * spacing[a]));
    }
    // A little below the bound, so that rounding never skips a real update.
    lowerBound = static_cast<float>(0.999 /
      std::sqrt(1.0 / (spacing[0] * spacing[0]) + 1.0 / (spacing[1] * spacing[1]) +
        1.0 / (spacing[2] * spacing[2])));
    invTauH = static_cast<float>(1.0 / std::min({ spacing[0], spacing[1], spacing[2] }));
    alphaThird = static_cast<float>(opacity / 3.0);
    thirdClear = static_cast<float>((1.0 - opacity) / 3.0);
  }

  /// A third of the transmittance of a voxel with signed distance d (Eq. 7), made
  /// translucent by Eq. 8: 1/3 - alpha/3 + alpha/3 * opaque. Eq. 6's mean of three then
  /// needs no multiply after the sum, which shortens the chain from voxel to voxel.
  float tauThird(float d) const
  {
    const float opaque = std::min(1.0f, std::max(0.0f, d * invTauH + 0.5f));
    return alphaThird * opaque + thirdClear;
  }
};

/// The Godunov upwind update (Eq. 1, anisotropic form): the largest u with
/// sum_i max(u - a_i, 0)^2 / h_i^2 = 1, trying the active sets of the 1, 2, 3 smallest a_i.
/// Infinite neighbours need no special case: they never enter an accepted active set.
inline float godunov(float ax, float ay, float az, const SweepConstants& k)
{
  float a[3] = { ax, ay, az };
  float h[3] = { k.h[0], k.h[1], k.h[2] };
  float w[3] = { k.w[0], k.w[1], k.w[2] };
  auto order = [&](int i, int j) {
    if (a[j] < a[i])
    {
      std::swap(a[i], a[j]);
      std::swap(h[i], h[j]);
      std::swap(w[i], w[j]);
    }
  };
  order(0, 1);
  order(1, 2);
  order(0, 1);
  const float u1 = a[0] + h[0];
  if (u1 <= a[1])
  {
    return u1;
  }
  // The quadratics in difference form: no cancellation between large a_i.
  const float d01 = a[1] - a[0];
  float sumW = w[0] + w[1];
  float disc = sumW - w[0] * w[1] * d01 * d01;
  const float u2 = (a[0] * w[0] + a[1] * w[1] + std::sqrt(std::max(0.0f, disc))) / sumW;
  if (u2 <= a[2])
  {
    return u2;
  }
  const float d02 = a[2] - a[0], d12 = a[2] - a[1];
  sumW += w[2];
  disc = sumW - (w[0] * w[1] * d01 * d01 + w[0] * w[2] * d02 * d02 + w[1] * w[2] * d12 * d12);
  return (a[0] * w[0] + a[1] * w[1] + a[2] * w[2] + std::sqrt(std::max(0.0f, disc))) / sumW;
}

/// One row of a sweep. Pointers are at the row's first voxel in sweep order; the row
/// advances by Step (+1 or -1). dy/dz and vy/vz are the upwind row and plane (a row of
/// open sky, D = +inf and V = 1, outside the volume); startD/startV, the x-upwind
/// neighbour of the first voxel (the open sky, or a ghost voxel of a block). scratch:
/// 3 x the row's length, the row's upwind terms (UpwindTerms).
struct RowView
{
  float* d;
  const float* dy;
  const float* dz;
  const std::uint64_t* fixedWords; // FixedMask, bit fixedIndex + x for voxel x of the row
  std::int64_t fixedIndex;
  float* v;
  const float* vy;
  const float* vz;
  float startD;
  float startV;
  float* scratch;
};

struct RowResult
{
  float largestChange = 0.0f; // of finite |D|
  bool reachedNew = false;    // some |D| went from infinity to finite
};

/// What each voxel of a row takes from its upwind row and plane, and the transmittance
/// of its D as the sweep finds it: nothing there depends on the row's own x chain, so it
/// is computed for the whole row first, in vector registers, and the serial loop keeps
/// only the chain (Eq. 6's multiply-add, the Godunov update). Indexed like the row's
/// voxels: element x at the returned pointers' [x].
struct UpwindTerms
{
  float* nearest; // min(|dy|, |dz|)
  float* inflow;  // Eq. 6's terms of the upwind row and plane: vy tau/3(dy) + vz tau/3(dz)
  float* tau;     // tau/3(d), d before this row's update

  template <int Step, bool Visibility>
  static UpwindTerms of(const RowView& row, std::int64_t count, const SweepConstants& k)
  {
    // In memory order, from the row's lowest address.
    const std::int64_t low = Step > 0 ? 0 : -(count - 1);
    float* __restrict nearest = row.scratch;
    float* __restrict inflow = row.scratch + count;
    float* __restrict tau = row.scratch + 2 * count;
    const float* __restrict d = row.d + low;
    const float* __restrict dy = row.dy + low;
    const float* __restrict dz = row.dz + low;
    for (std::int64_t i = 0; i < count; ++i)
      nearest[i] = std::min(std::abs(dy[i]), std::abs(dz[i]));
    if (Visibility)
    {
      const SweepConstants c = k; // a copy the stores cannot alias
      const float* __restrict vy = row.vy + low;
      const float* __restrict vz = row.vz + low;
      for (std::int64_t i = 0; i < count; ++i)
      {
        inflow[i] = vy[i] * c.tauThird(dy[i]) + vz[i] * c.tauThird(dz[i]);
        tau[i] = c.tauThird(d[i]);
      }
    }
    return { nearest - low, inflow - low, tau - low };
  }
};

template <int Step, bool Visibility>
RowResult sweepRow(const RowView& row, std::int64_t count, const SweepConstants& k)
{
  const UpwindTerms upwind = UpwindTerms::of<Step, Visibility>(row, count, k);
  RowResult result;
  float previousD = row.startD; // the x-upwind neighbour
  float previousV = row.startV;
  float previousTau = k.tauThird(previousD);
  for (std::int64_t i = 0; i < count; ++i)
  {
    const std::int64_t x = i * Step;
    if (Visibility)
    {
      // Eq. 6 with the upwind D as this sweep has left it.
      previousV = previousV * previousTau + upwind.inflow[x];
      row.v[x] = previousV;
      previousTau = upwind.tau[x];
    }
    float d = row.d[x];
    const float ax = std::abs(previousD);
    const float old = std::abs(d);
    const std::int64_t f = row.fixedIndex + x;
    const bool fixed = (row.fixedWords[f >> 6] >> (f & 63)) & 1u;
    if (!fixed && old > std::min(ax, upwind.nearest[x]) + k.lowerBound)
    {
      const float candidate = godunov(ax, std::abs(row.dy[x]), std::abs(row.dz[x]), k);
      if (candidate < old)
      {
        if (old < kInfinity)
        {
          result.largestChange = std::max(result.largestChange, old - candidate);
        }
        else
        {
          result.reachedNew = true;
        }
        d = std::copysign(candidate, d);
        row.d[x] = d;
        if (Visibility)
          previousTau = k.tauThird(d);
      }
    }
    previousD = d;
  }
  return result;
}

using RowFunction = RowResult (*)(const RowView&, std::int64_t, const SweepConstants&);

RowFunction rowFunction(int xDirection, bool visibility)
{
  if (xDirection > 0)
  {
    return visibility ? &sweepRow<1, true> : &sweepRow<1, false>;
  }
  return visibility ? &sweepRow<-1, true> : &sweepRow<-1, false>;
}

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
  {}

  /// The sweep of `octant` over the own voxels. Returns false when cancelled.
  bool sweep(int octant, bool visibility, const Execution& execution, RowResult& total)
  {
    const std::int64_t planes = this->Layout.size[2];
    SweepState state(octant, visibility, planes);
    // One plane per chunk: member t sweeps planes t, t + T, ... (the wavefront, Parallel.h).
    const bool finished = detail::parallelFor(planes, static_cast<int>(planes), this->Threads, execution,
      [&](std::int64_t k0, std::int64_t k1, detail::ChunkProgress& progress) {
        std::vector<float> scratch(static_cast<std::size_t>(3 * this->Layout.size[0]));
        for (std::int64_t k = k0; k < k1 && !progress.stopped(); ++k)
        {
          if (!this->sweepPlane(state, k, scratch.data(), progress))
          {
            return;
          }
          progress.advance();
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
    {}
  };

  /// Plane k of the sweep (k counts in sweep order). Waits, row by row, for plane k - 1.
  bool sweepPlane(SweepState& state, std::int64_t k, float* scratch, const detail::ChunkProgress& progress)
  {
    const Grid& g = this->Storage;
    const Index3& n = this->Layout.size;
    const std::int64_t z = this->Layout.offset[2] + (state.dir[2] > 0 ? k : n[2] - 1 - k);
    const bool ghosted = this->Layout.ghosted;
    RowResult& result = state.planeResults[k];
    for (std::int64_t j = 0; j < n[1]; ++j)
    {
      if (k > 0 && !waitForRow(state.rowsDone[k - 1], j, progress))
      {
        return false;
      }
      const std::int64_t y = this->Layout.offset[1] + (state.dir[1] > 0 ? j : n[1] - 1 - j);
      const RowResult r = state.rowKernel(
        this->rowView(state, y, z, ghosted || j > 0, ghosted || k > 0, scratch), n[0], this->Constants);
      result.largestChange = std::max(result.largestChange, r.largestChange);
      result.reachedNew = result.reachedNew || r.reachedNew;
      if (state.visibility && !this->Visibility.kept)
      {
        float* sum = this->Visibility.sum + g.index(this->Layout.offset[0], y, z);
        const float* v = this->Visibility.row(state.octant, y, z, g) + this->Layout.offset[0];
        for (std::int64_t x = 0; x < n[0]; ++x)
        {
          sum[x] += v[x];
        }
      }
      state.rowsDone[k].done.store(j + 1, std::memory_order_release);
    }
    return true;
  }

  /// Row (y, z) (storage coordinates) with its upwind row and plane, or the open sky where
  /// they are outside; the x-upwind neighbour of its first voxel likewise (from storage when
  /// the layout is ghosted).
  RowView rowView(const SweepState& state, std::int64_t y, std::int64_t z, bool hasUpwindRow, bool hasUpwindPlane,
    float* scratch)
  {
    const Grid& g = this->Storage;
    const std::int64_t sky0 = state.dir[0] > 0 ? 0 : this->Layout.size[0] - 1; // in the sky rows
    const std::int64_t x0 = this->Layout.offset[0] + sky0;
    const std::int64_t rowStep = state.dir[1] * g.nx, planeStep = state.dir[2] * g.plane;
    const std::int64_t i = g.index(x0, y, z);
    const bool ghosted = this->Layout.ghosted;
    RowView row{ this->Distance + i, hasUpwindRow ? this->Distance + i - rowStep : this->SkyDistance.data() + sky0,
      hasUpwindPlane ? this->Distance + i - planeStep : this->SkyDistance.data() + sky0, this->Fixed, i, nullptr,
      nullptr, nullptr, ghosted ? this->Distance[i - state.dir[0]] : kInfinity, 1.0f, scratch };
    if (state.visibility)
    {
      VisibilityStore& vis = this->Visibility;
      row.v = vis.row(state.octant, y, z, g) + x0;
      row.vy = hasUpwindRow ? row.v - state.dir[1] * vis.pitch(g) : this->SkyVisibility.data() + sky0;
      row.vz = hasUpwindPlane ? vis.row(state.octant, y, z - state.dir[2], g) + x0 : this->SkyVisibility.data() + sky0;
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
      detail::parallelFor(layout.storage.count, 4 * threads, threads, [&](std::int64_t begin, std::int64_t end) {
        std::fill(vis.sum + begin, vis.sum + end, 0.0f);
      });
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
