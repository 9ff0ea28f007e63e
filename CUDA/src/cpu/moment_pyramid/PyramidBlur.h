// The one blur of the moment pyramid (Penner & Mitchell 2008; docs/methods.md,
// Penner and Mitchell): blurDecimate turns a "source" grid into the next level, a
// separable normalised 5-tap Gaussian (sigma = 1 voxel, weights renormalised where the
// kernel is clipped by the volume) evaluated only at the kept voxels (every voxel, or
// every second one per axis). It streams: for each output slice, rows are first blurred
// along z straight from the source (5 rows in, one row out), kept in a ring of 5 rows,
// blurred along y from the ring and along x into the output. The working set is a handful
// of rows, so the passes run from L1/L2 and never write a full-size temporary.
//
// A SliceBlur can be narrowed to a window of each slice (a tile of level 0 built on
// demand, LevelTiles.h): it then blurs only the input columns the window's taps reach.
// Every output voxel takes the same operations in the same order either way, so a tile
// equals the same voxels of the whole level bit for bit.
//
// Precision. The source supplies per voxel d = x - K (K: the volume's sampled mean) and
// the second moment s = var + d^2 (var = 0 for the raw volume), both in double; the blur
// accumulates in double and the level stores mean = A + K and variance = max(0, B - A^2)
// as float. The next level is built from those stored floats: blurring var + (mean-K)^2
// is the same second moment, and the cancellation B - A^2 happens in double on values
// shifted by K, so the only loss is the float rounding of the stored mean and variance
// (relative 6e-8 each), never the catastrophic E[v^2] - mu^2 of float moments.
#pragma once

#include "vao/VarianceOcclusionMap.h"

#include "VolumeAccess.h"
#include "cpu/common/ConcurrentRange.h"
#include "cpu/common/Parallel.h"
#include "cpu/moment_pyramid/PyramidPlan.h"
#include "cpu/moment_pyramid/PyramidRows.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace vao
{
namespace detail
{
namespace pyramid
{

/// Raw volume as a source: d = v - K, s = d^2.
template <class T>
struct RawSource
{
  TypedVolume<T> volume;
  double shift;

  Index3 dims() const { return volume.dims; }
  /// a[i] = sum_k w[k] d(x0 + i, y, z_k), b[i] = sum_k w[k] s(x0 + i, y, z_k) for i in
  /// [0, count) over the 5 rows (y, z[k]), for the `rows` rows y = y0, y0 + 1, ... (their
  /// outputs outRowStride apart); a clipped tap has weight 0 and a valid (clamped) row.
  void blurRows(std::int64_t y0, std::int64_t rows, const std::int64_t* z, const double* w,
    std::int64_t x0, std::int64_t count, double* a, double* b, std::int64_t outRowStride,
    SimdTier simd) const
  {
    const T* first[kTaps];
    for (int k = 0; k < kTaps; ++k)
    {
      first[k] = volume.row(y0, z[k]) + x0 * volume.stride;
    }
    const std::int64_t inRowStride = volume.dims[0] * volume.stride;
    if (volume.stride == 1)
      runRows<RawPlane<T, true>>(
        simd, &first[0], w, shift, std::int64_t(1), count, rows, inRowStride, outRowStride, a, b);
    else
      runRows<RawPlane<T, false>>(
        simd, &first[0], w, shift, volume.stride, count, rows, inRowStride, outRowStride, a, b);
  }
};

/// Stored moments of a level as a source: d = mean - K, s = variance + d^2. `at(x, y, z)`
/// gives where voxel (x, y, z)'s mean and variance are, the row's next voxels following
/// (a whole level, a ring of its slices, a block of it).
template <class Voxels>
struct StoredSource
{
  Voxels at;
  Index3 size; // the whole level's dims (the blur's clipping)
  double shift;

  Index3 dims() const { return size; }
  /// RawSource::blurRows from the stored moments.
  void blurRows(std::int64_t y0, std::int64_t rows, const std::int64_t* z, const double* w,
    std::int64_t x0, std::int64_t count, double* a, double* b, std::int64_t outRowStride,
    SimdTier simd) const
  {
    const float* means[kTaps];
    const float* variances[kTaps];
    for (int k = 0; k < kTaps; ++k)
    {
      const auto voxel = at(x0, y0, z[k]);
      means[k] = voxel.first;
      variances[k] = voxel.second;
    }
    // The voxels' rows are evenly spaced: the next row's first one gives the stride.
    const std::int64_t inRowStride = rows > 1 ? at(x0, y0 + 1, z[0]).first - means[0] : 0;
    runRows<LevelPlane>(
      simd, &means[0], &variances[0], w, shift, count, rows, inRowStride, outRowStride, a, b);
  }
};

/// The voxels of a whole stored level.
struct LevelVoxels
{
  const MomentLevel* level;
  std::pair<const float*, const float*> operator()(
    std::int64_t x, std::int64_t y, std::int64_t z) const
  {
    const std::int64_t offset = (z * level->dims[1] + y) * level->dims[0] + x;
    return { level->mean.data() + offset, level->variance.data() + offset };
  }
};

inline StoredSource<LevelVoxels> levelSource(const MomentLevel& level, double shift)
{
  return { LevelVoxels{ &level }, level.dims, shift };
}

/// What every output slice of one blurDecimate shares: sizes and weights.
struct BlurPlan
{
  Index3 in;  // source dims
  Index3 out; // kept voxels per axis
  int step;
  double shift;
  std::vector<double> wx, wy, wz; // clipped weights per kept index (axisWeights)
  double kernel[kTaps];           // the unclipped weights
  SimdTier simd = cpuSimdTier();

  BlurPlan(const Index3& n, int keepEvery, double k)
    : in(n)
    , step(keepEvery)
    , shift(k)
  {
    out = keptDims(n, step);
    wx = axisWeights(n[0], out[0], step);
    wy = axisWeights(n[1], out[1], step);
    wz = axisWeights(n[2], out[2], step);
    double sum = 0.0;
    for (int k = 0; k < kTaps; ++k)
    {
      kernel[k] = std::exp(-0.5 * (k - kHalf) * (k - kHalf));
      sum += kernel[k];
    }
    for (double& w : kernel)
    {
      w /= sum;
    }
  }
};

/// The output voxels [x0, x1) x [y0, y1) of each slice a SliceBlur computes.
struct SliceWindow
{
  std::int64_t x0, x1, y0, y1;
};

/// The rows one thread keeps while it blurs output slices: a ring of z-blurred rows
/// (tagged by input y) and one y-blurred row with zero padding for the x taps.
template <class Source>
class SliceBlur
{
public:
  SliceBlur(const Source& source, const BlurPlan& plan)
    : Src(source)
    , Plan(plan)
    , RingStride((plan.in[0] + 7) / 8 * 8 + 8)
    , Rings(static_cast<std::size_t>(2 * kTaps * RingStride + kRingSkew))
    , RowA(static_cast<std::size_t>(plan.in[0] + 2 * kHalf + 2 * plan.step), 0.0)
    , RowB(RowA.size(), 0.0)
  {
    this->setWindow({ 0, plan.out[0], 0, plan.out[1] });
  }

  /// Narrows the slices to a window of output voxels: only the input columns its taps
  /// reach are blurred. A window of few rows (a tile's block) is blurred a plane at a
  /// time (slicePlane).
  void setWindow(const SliceWindow& window)
  {
    const BlurPlan& p = this->Plan;
    this->Window = window;
    this->Xa = std::max<std::int64_t>(0, window.x0 * p.step - kHalf);
    this->Xb = std::min<std::int64_t>(p.in[0], (window.x1 - 1) * p.step + kHalf + 1);
    this->Ya = std::max<std::int64_t>(0, window.y0 * p.step - kHalf);
    this->Yb = std::min<std::int64_t>(p.in[1], (window.y1 - 1) * p.step + kHalf + 1);
    const std::int64_t width = this->Xb - this->Xa;
    this->PlaneMode =
      this->Yb - this->Ya <= kPlaneRows && width <= kPlaneWidth && window.y1 > window.y0;
    if (this->PlaneMode)
    {
      // Each y-blurred row padded as RowA is, zeros where the x taps leave the volume.
      this->PaddedWidth = width + 2 * kHalf + 2 * p.step;
      const auto rows = static_cast<std::size_t>(window.y1 - window.y0);
      this->PlaneA.resize(static_cast<std::size_t>((this->Yb - this->Ya) * width));
      this->PlaneB.resize(this->PlaneA.size());
      this->YRowsA.assign(rows * static_cast<std::size_t>(this->PaddedWidth), 0.0);
      this->YRowsB.assign(this->YRowsA.size(), 0.0);
    }
  }

  /// Output slice zo within the window: rows(yo) gives the float pointers where the mean
  /// and variance of output voxel (window.x0, yo, zo) go (the rest of the row follows).
  template <class Rows>
  void slice(std::int64_t zo, Rows&& rows)
  {
    const BlurPlan& p = this->Plan;
    const std::int64_t xa = this->Xa, width = this->Xb - this->Xa;
    for (int k = 0; k < kTaps; ++k) // clipped taps read a valid row with weight 0
    {
      this->ZRows[k] = std::min(std::max<std::int64_t>(zo * p.step + k - kHalf, 0), p.in[2] - 1);
      this->Tags[k] = -1;
    }
    if (this->PlaneMode)
    {
      this->slicePlane(zo, rows);
      return;
    }
    for (std::int64_t yo = this->Window.y0; yo < this->Window.y1; ++yo)
    {
      const double* ia[kTaps];
      const double* ib[kTaps];
      for (int k = 0; k < kTaps; ++k)
      {
        const int slot = this->zBlurredRow(
          std::min(std::max<std::int64_t>(yo * p.step + k - kHalf, 0), p.in[1] - 1), zo);
        ia[k] = this->ringA(slot) + xa;
        ib[k] = this->ringB(slot) + xa;
      }
      runRows<ColumnRows>(p.simd, &ia[0], &ib[0], &p.wy[yo * kTaps], width,
        this->RowA.data() + kHalf + xa, this->RowB.data() + kHalf + xa);
      const auto out = rows(yo);
      this->xPass(this->RowA.data(), this->RowB.data(), 0, out.first, out.second);
    }
  }

private:
  // A window whose taps reach at most this many input rows, of at most this many voxels,
  // is blurred a plane at a time.
  static constexpr std::int64_t kPlaneRows = 32;
  static constexpr std::int64_t kPlaneWidth = 4096;

  /// slice() of a window of few rows: every input row its taps reach blurred along z in
  /// one call, then every output row along y in one, then each along x: the same numbers
  /// as row by row, without a call per row of a dozen voxels.
  template <class Rows>
  void slicePlane(std::int64_t zo, Rows&& rows)
  {
    const BlurPlan& p = this->Plan;
    const std::int64_t width = this->Xb - this->Xa;
    this->Src.blurRows(this->Ya, this->Yb - this->Ya, this->ZRows, &p.wz[zo * kTaps], this->Xa,
      width, this->PlaneA.data(), this->PlaneB.data(), width, p.simd);
    runRows<ColumnPlane>(p.simd, static_cast<const double*>(this->PlaneA.data()),
      static_cast<const double*>(this->PlaneB.data()), width, this->Ya, p.in[1],
      static_cast<std::int64_t>(p.step), p.wy.data(), this->Window.y0, this->Window.y1, width,
      this->YRowsA.data() + kHalf, this->YRowsB.data() + kHalf, this->PaddedWidth);
    for (std::int64_t yo = this->Window.y0; yo < this->Window.y1; ++yo)
    {
      const std::int64_t row = (yo - this->Window.y0) * this->PaddedWidth;
      const auto out = rows(yo);
      this->xPass(
        this->YRowsA.data() + row, this->YRowsB.data() + row, this->Xa, out.first, out.second);
    }
  }

  /// The ring slot holding input row y blurred along z (computed when missing).
  int zBlurredRow(std::int64_t y, std::int64_t zo)
  {
    const int slot = static_cast<int>(y % kTaps);
    if (this->Tags[slot] != y)
    {
      this->Src.blurRows(y, 1, this->ZRows, &this->Plan.wz[zo * kTaps], this->Xa,
        this->Xb - this->Xa, this->ringA(slot) + this->Xa, this->ringB(slot) + this->Xa, 0,
        this->Plan.simd);
      this->Tags[slot] = y;
    }
    return slot;
  }

  /// x pass at the window's kept voxels of the y-blurred row pa, pb: pa[i + kHalf] is its
  /// value at input x = lo + i; the padding is zero and so are the clipped weights.
  /// Interior voxels take the constant weights in a vectorised loop. mean[0] is output
  /// voxel window.x0.
  void xPass(
    const double* pa, const double* pb, std::int64_t lo, float* mean, float* variance) const
  {
    const BlurPlan& p = this->Plan;
    const std::int64_t x0 = this->Window.x0, x1 = this->Window.x1, step = p.step;
    // The unclipped outputs of the whole row, then of the window.
    const std::int64_t rowBegin = std::min<std::int64_t>(p.out[0], (kHalf + step - 1) / step);
    const std::int64_t rowEnd = std::max<std::int64_t>(
      rowBegin, std::min<std::int64_t>(p.out[0], (p.in[0] - 1 - kHalf) / step + 1));
    const std::int64_t begin = std::max(x0, std::min(x1, rowBegin));
    const std::int64_t end = std::max(begin, std::min(x1, rowEnd));
    auto clipped = [&](std::int64_t xo)
    {
      const double* w = &p.wx[xo * kTaps];
      double sa = 0.0, sb = 0.0;
      for (int k = 0; k < kTaps; ++k)
      {
        sa += w[k] * pa[xo * step + k - lo];
        sb += w[k] * pb[xo * step + k - lo];
      }
      blur::levelMoments(sa, sb, p.shift, mean[xo - x0], variance[xo - x0]);
    };
    for (std::int64_t xo = x0; xo < begin; ++xo)
      clipped(xo);
    // InteriorRow's output xo - begin reads from pa + step * xo - lo.
    const std::int64_t from = step * begin - lo;
    if (step == 1)
      runRows<InteriorRow<1>>(p.simd, pa + from, pb + from, &p.kernel[0], p.shift, std::int64_t(0),
        end - begin, mean + (begin - x0), variance + (begin - x0));
    else
      runRows<InteriorRow<2>>(p.simd, pa + from, pb + from, &p.kernel[0], p.shift, std::int64_t(0),
        end - begin, mean + (begin - x0), variance + (begin - x0));
    for (std::int64_t xo = end; xo < x1; ++xo)
      clipped(xo);
  }

  /// A ring slot's z-blurred row (first moment, second moment). Rows of a power-of-two
  /// width a page apart would share one set of the L1 cache, and the y pass reads ten of
  /// them at once, more than its ways: each row starts a cache line further along.
  double* ringA(int slot) { return this->Rings.data() + slot * this->RingStride; }
  double* ringB(int slot)
  {
    return this->Rings.data() + (kTaps + slot) * this->RingStride + kRingSkew;
  }
  static constexpr std::int64_t kRingSkew = 5 * 8; // the second moments' rows: 5 lines on

  const Source& Src;
  const BlurPlan& Plan;
  std::int64_t RingStride;
  std::vector<double> Rings;
  std::int64_t Tags[kTaps];
  std::int64_t ZRows[kTaps];
  std::vector<double> RowA, RowB;
  SliceWindow Window{};
  std::int64_t Xa = 0, Xb = 0; // input columns the window's taps reach
  std::int64_t Ya = 0, Yb = 0; // input rows the window's taps reach
  bool PlaneMode = false;
  std::int64_t PaddedWidth = 0;
  std::vector<double> PlaneA, PlaneB; // the plane's z-blurred input rows [Ya, Yb)
  std::vector<double> YRowsA, YRowsB; // its y-blurred output rows, padded
};

/// The mean and variance rows of output slice zo of a whole level (dims `out`).
inline auto levelRows(float* mean, float* variance, const Index3& out, std::int64_t zo)
{
  return [=](std::int64_t yo)
  {
    const std::int64_t o = (zo * out[1] + yo) * out[0];
    return std::make_pair(mean + o, variance + o);
  };
}

/// Blurs the source and keeps every `step`-th voxel per axis (step 1 or 2) into `out`
/// (dims, mean and variance and their ranges, each slice's taken while it is in the
/// cache; geometry is the caller's). Returns false when cancelled.
template <class Source>
bool blurDecimate(const Source& source, int step, double shift, MomentLevel& out,
  const Execution& execution, int threads)
{
  const BlurPlan plan(source.dims(), step, shift);
  out.dims = plan.out;
  // Every voxel is written below: a level of the same size (a rebuild) keeps its storage
  // untouched, which saves the page faults of fresh arrays.
  const auto outCount = static_cast<std::size_t>(plan.out[0] * plan.out[1] * plan.out[2]);
  out.mean.resize(outCount);
  out.variance.resize(outCount);
  out.meanRange = out.varianceRange = OutputRange{};
  const int chunks =
    static_cast<int>(std::min<std::int64_t>(plan.out[2], std::max(1, threads) * 4));
  const std::int64_t slice = plan.out[0] * plan.out[1];
  ConcurrentRange means, variances;
  const bool done = parallelFor(plan.out[2], chunks, threads, execution,
    [&](std::int64_t zBegin, std::int64_t zEnd, ChunkProgress& progress)
    {
      SliceBlur<Source> blur(source, plan);
      for (std::int64_t zo = zBegin; zo < zEnd; ++zo)
      {
        blur.slice(zo, levelRows(out.mean.data(), out.variance.data(), plan.out, zo));
        means.add(out.mean.data() + zo * slice, slice);
        variances.add(out.variance.data() + zo * slice, slice);
        if (!progress.advance())
        {
          return;
        }
      }
    });
  if (done)
  {
    out.meanRange = means.result();
    out.varianceRange = variances.result();
  }
  return done;
}

/// Levels [from, levels.size()) of a pyramid, each blurred from the one before it and
/// kept every second voxel; level l reports its progress on stage(l). Returns false when
/// cancelled.
template <class Stage>
bool blurCoarserLevels(
  std::vector<MomentLevel>& levels, int from, double shift, int threads, Stage&& stage)
{
  for (int l = from; l < static_cast<int>(levels.size()); ++l)
  {
    if (!blurDecimate(levelSource(levels[l - 1], shift), 2, shift, levels[l], stage(l), threads))
      return false;
  }
  return true;
}

} // namespace pyramid
} // namespace detail
} // namespace vao
