// The moment pyramid of variance occlusion maps (Penner & Mitchell 2008; the Penner &
// Mitchell section of METHODS.md).
//
// One routine, blurDecimate, turns a "source" grid into the next level: a separable
// normalised 5-tap Gaussian (sigma = 1 voxel, weights renormalised where the kernel is
// clipped by the volume) evaluated only at the kept voxels (every voxel, or every second
// one per axis). It streams: for each output slice, rows are first blurred along z
// straight from the source (5 rows in, one row out), kept in a ring of 5 rows, blurred
// along y from the ring and along x into the output. The working set is a handful of
// rows, so the passes run from L1/L2 and never write a full-size temporary.
//
// Precision. The source supplies per voxel d = x - K (K: the volume's sampled mean) and
// the second moment s = var + d^2 (var = 0 for the raw volume), both in double; the blur
// accumulates in double and the level stores mean = A + K and variance = max(0, B - A^2)
// as float. The next level is built from those stored floats: blurring var + (mean-K)^2
// is the same second moment, and the cancellation B - A^2 happens in double on values
// shifted by K, so the only loss is the float rounding of the stored mean and variance
// (relative 6e-8 each), never the catastrophic E[v^2] - mu^2 of float moments.
#include "vao/VarianceOcclusionMap.h"
#include "vao/Validation.h"

#include "Parallel.h"
#include "PyramidPlan.h"
#include "PyramidRows.h"
#include "VolumeAccess.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

namespace vao
{
namespace
{

using namespace detail;
using namespace detail::pyramid;

/// Raw volume as a source: d = v - K, s = d^2.
template <class T>
struct RawSource
{
  detail::TypedVolume<T> volume;
  double shift;

  Index3 dims() const { return volume.dims; }
  /// a[x] = sum_k w[k] d(x, y, z_k), b[x] = sum_k w[k] s(x, y, z_k) over the 5 rows
  /// (y, z[k]); a clipped tap has weight 0 and a valid (clamped) row.
  void blurRows(std::int64_t y, const std::int64_t* z, const double* w, double* a, double* b, SimdTier simd) const
  {
    const T* rows[kTaps];
    for (int k = 0; k < kTaps; ++k)
    {
      rows[k] = volume.row(y, z[k]);
    }
    const std::int64_t nx = volume.dims[0];
    if (volume.stride == 1)
      runRows<RawRows<T, true>>(simd, &rows[0], w, shift, std::int64_t(1), nx, a, b);
    else
      runRows<RawRows<T, false>>(simd, &rows[0], w, shift, volume.stride, nx, a, b);
  }
};

/// A stored level as a source: d = mean - K, s = variance + d^2.
struct LevelSource
{
  const MomentLevel* level;
  double shift;

  Index3 dims() const { return level->dims; }
  void blurRows(std::int64_t y, const std::int64_t* z, const double* w, double* a, double* b, SimdTier simd) const
  {
    const float* means[kTaps];
    const float* variances[kTaps];
    for (int k = 0; k < kTaps; ++k)
    {
      const std::int64_t offset = (z[k] * level->dims[1] + y) * level->dims[0];
      means[k] = level->mean.data() + offset;
      variances[k] = level->variance.data() + offset;
    }
    runRows<LevelRows>(simd, &means[0], &variances[0], w, shift, level->dims[0], a, b);
  }
};

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

/// The rows one thread keeps while it blurs output slices: a ring of z-blurred rows
/// (tagged by input y) and one y-blurred row with zero padding for the x taps.
template <class Source>
class SliceBlur
{
public:
  SliceBlur(const Source& source, const BlurPlan& plan)
    : Src(source)
    , Plan(plan)
    , RingA(static_cast<std::size_t>(kTaps * plan.in[0]))
    , RingB(static_cast<std::size_t>(kTaps * plan.in[0]))
    , RowA(static_cast<std::size_t>(plan.in[0] + 2 * kHalf + 2 * plan.step), 0.0)
    , RowB(RowA.size(), 0.0)
  {
  }

  /// Output slice zo of the level into mean and variance (level-sized arrays).
  void slice(std::int64_t zo, float* mean, float* variance)
  {
    const BlurPlan& p = this->Plan;
    const std::int64_t nx = p.in[0];
    for (int k = 0; k < kTaps; ++k) // clipped taps read a valid row with weight 0
    {
      this->ZRows[k] = std::min(std::max<std::int64_t>(zo * p.step + k - kHalf, 0), p.in[2] - 1);
      this->Tags[k] = -1;
    }
    for (std::int64_t yo = 0; yo < p.out[1]; ++yo)
    {
      const double* ia[kTaps];
      const double* ib[kTaps];
      for (int k = 0; k < kTaps; ++k)
      {
        const int slot = this->zBlurredRow(std::min(std::max<std::int64_t>(yo * p.step + k - kHalf, 0), p.in[1] - 1), zo);
        ia[k] = &this->RingA[slot * nx];
        ib[k] = &this->RingB[slot * nx];
      }
      runRows<ColumnRows>(p.simd, &ia[0], &ib[0], &p.wy[yo * kTaps], nx, this->RowA.data() + kHalf,
        this->RowB.data() + kHalf);
      const std::int64_t o = (zo * p.out[1] + yo) * p.out[0];
      this->xPass(mean + o, variance + o);
    }
  }

private:
  /// The ring slot holding input row y blurred along z (computed when missing).
  int zBlurredRow(std::int64_t y, std::int64_t zo)
  {
    const int slot = static_cast<int>(y % kTaps);
    if (this->Tags[slot] != y)
    {
      const std::int64_t nx = this->Plan.in[0];
      this->Src.blurRows(y, this->ZRows, &this->Plan.wz[zo * kTaps], &this->RingA[slot * nx],
        &this->RingB[slot * nx], this->Plan.simd);
      this->Tags[slot] = y;
    }
    return slot;
  }

  /// x pass at the kept voxels of the y-blurred row; the padding is zero and so are the
  /// clipped weights. Interior voxels take the constant weights in a vectorised loop.
  void xPass(float* mean, float* variance) const
  {
    const BlurPlan& p = this->Plan;
    const double* pa = this->RowA.data(); // pa[i + kHalf] = row value at input x = i
    const double* pb = this->RowB.data();
    const std::int64_t m = p.out[0], step = p.step;
    const std::int64_t interiorBegin = std::min<std::int64_t>(m, (kHalf + step - 1) / step);
    const std::int64_t interiorEnd =
      std::max<std::int64_t>(interiorBegin, std::min<std::int64_t>(m, (p.in[0] - 1 - kHalf) / step + 1));
    auto clipped = [&](std::int64_t xo) {
      const double* w = &p.wx[xo * kTaps];
      double sa = 0.0, sb = 0.0;
      for (int k = 0; k < kTaps; ++k)
      {
        sa += w[k] * pa[xo * step + k];
        sb += w[k] * pb[xo * step + k];
      }
      blur::levelMoments(sa, sb, p.shift, mean[xo], variance[xo]);
    };
    for (std::int64_t xo = 0; xo < interiorBegin; ++xo)
      clipped(xo);
    if (step == 1)
      runRows<InteriorRow<1>>(p.simd, pa, pb, &p.kernel[0], p.shift, interiorBegin, interiorEnd, mean, variance);
    else
      runRows<InteriorRow<2>>(p.simd, pa, pb, &p.kernel[0], p.shift, interiorBegin, interiorEnd, mean, variance);
    for (std::int64_t xo = interiorEnd; xo < m; ++xo)
      clipped(xo);
  }

  const Source& Src;
  const BlurPlan& Plan;
  std::vector<double> RingA, RingB;
  std::int64_t Tags[kTaps];
  std::int64_t ZRows[kTaps];
  std::vector<double> RowA, RowB;
};

/// Blurs the source and keeps every `step`-th voxel per axis (step 1 or 2) into `out`
/// (dims, mean and variance; geometry is the caller's). Returns false when cancelled.
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
  const int chunks = static_cast<int>(std::min<std::int64_t>(plan.out[2], std::max(1, threads) * 4));
  return detail::parallelFor(plan.out[2], chunks, threads, execution,
    [&](std::int64_t zBegin, std::int64_t zEnd, detail::ChunkProgress& progress) {
      SliceBlur<Source> blur(source, plan);
      for (std::int64_t zo = zBegin; zo < zEnd; ++zo)
      {
        blur.slice(zo, out.mean.data(), out.variance.data());
        if (!progress.advance())
        {
          return;
        }
      }
    });
}

Status buildPyramid(const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const PyramidParameters& parameters,
  std::vector<MomentLevel>& pyramid, const Execution& execution)
{
  PyramidSetup setup;
  const Status status = preparePyramid(volume, origin, spacing, parameters, setup);
  if (!status.ok)
  {
    pyramid.clear();
    return status;
  }
  const int threads = detail::resolveThreadCount(execution.threads);
  const double shift = setup.shift;
  const int levels = parameters.levels;
  // Reuse the storage of a previous build (same sizes: no allocation, no page faults).
  std::vector<MomentLevel> result = std::move(pyramid);
  pyramid.clear();
  result.resize(static_cast<std::size_t>(levels));
  const double stageWidth = 1.0 / levels;
  const bool firstDone = detail::dispatchScalarType(volume.type, [&](auto tag) {
    using T = decltype(tag);
    const RawSource<T> source{ detail::TypedVolume<T>(volume), shift };
    return blurDecimate(source, setup.firstStep, shift, result[0], detail::stageExecution(execution, 0.0, stageWidth), threads);
  });
  if (!firstDone)
  {
    return Status::cancelled();
  }
  for (int l = 1; l < levels; ++l)
  {
    const Execution stage = detail::stageExecution(execution, l * stageWidth, (l + 1) * stageWidth);
    if (!blurDecimate(LevelSource{ &result[l - 1], shift }, 2, shift, result[l], stage, threads))
    {
      return Status::cancelled();
    }
  }
  setLevelGeometry(result, origin, spacing, setup);
  pyramid = std::move(result);
  return Status::success();
}

} // namespace

namespace detail
{

Status preparePyramid(const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const PyramidParameters& parameters, PyramidSetup& setup)
{
  Status status = checkVolume(volume, 2, "the variance occlusion map");
  if (status.ok)
    status = checkSpacing(spacing);
  if (status.ok)
    status = checkFinitePoint(origin, "the origin");
  if (status.ok && (parameters.levels < 1 || parameters.levels > 16))
  {
    std::ostringstream why;
    why << "the number of pyramid levels must be in [1, 16], got " << parameters.levels;
    status = Status::failure(why.str());
  }
  const ValueScan scan = status.ok ? scanValues(volume) : ValueScan{};
  if (status.ok)
    status = finiteStatus(scan);
  if (status.ok)
    status = checkMomentMagnitude(scan);
  if (!status.ok)
  {
    return status;
  }
  setup.shift = dispatchScalarType(volume.type, [&](auto tag) {
    return sampledMean(TypedVolume<decltype(tag)>(volume));
  });
  setup.roundingVariance =
    sumRoundingVariance(std::max(std::abs(scan.maximum - setup.shift), std::abs(scan.minimum - setup.shift)));
  setup.firstStep = parameters.startAtHalfResolution ? 2 : 1;
  return Status::success();
}

Index3 keptDims(const Index3& in, int step)
{
  Index3 out;
  for (int a = 0; a < 3; ++a)
  {
    out[a] = step == 1 ? in[a] : (in[a] + 1) / 2;
  }
  return out;
}

/// Normalised weights of the clipped 5-tap Gaussian for each kept output index along one
/// axis of n input voxels: weights[o * 5 + k] for input index o * step + k - 2 (0 where
/// that input is outside [0, n)).
std::vector<double> axisWeights(std::int64_t n, std::int64_t outN, int step)
{
  static const double base[kTaps] = { std::exp(-2.0), std::exp(-0.5), 1.0, std::exp(-0.5),
    std::exp(-2.0) };
  std::vector<double> weights(static_cast<std::size_t>(outN * kTaps), 0.0);
  for (std::int64_t o = 0; o < outN; ++o)
  {
    const std::int64_t centre = o * step;
    double sum = 0.0;
    for (int k = 0; k < kTaps; ++k)
    {
      const std::int64_t i = centre + k - kHalf;
      sum += (i >= 0 && i < n) ? base[k] : 0.0;
    }
    for (int k = 0; k < kTaps; ++k)
    {
      const std::int64_t i = centre + k - kHalf;
      weights[o * kTaps + k] = (i >= 0 && i < n) ? base[k] / sum : 0.0;
    }
  }
  return weights;
}

void setLevelGeometry(std::vector<MomentLevel>& levels, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const PyramidSetup& setup)
{
  for (std::size_t l = 0; l < levels.size(); ++l)
  {
    MomentLevel& level = levels[l];
    level.origin = origin;
    for (int a = 0; a < 3; ++a)
    {
      level.spacing[a] = l == 0 ? spacing[a] * setup.firstStep : levels[l - 1].spacing[a] * 2.0;
    }
    // r_l: the 5-tap half-width (2 voxels) of the level's own grid, largest axis; it
    // doubles with every level.
    level.kernelRadius = 2.0 * std::max(level.spacing[0], std::max(level.spacing[1], level.spacing[2]));
    level.roundingVariance = setup.roundingVariance;
  }
}

} // namespace detail

Status buildMomentPyramid(const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const PyramidParameters& parameters,
  std::vector<MomentLevel>& pyramid, const Execution& execution)
{
  const Status status = catchOutOfMemory("the levels of the moment pyramid",
    [&] { return buildPyramid(volume, origin, spacing, parameters, pyramid, execution); });
  if (status.outOfMemory)
  {
    pyramid.clear();
  }
  return status;
}

} // namespace vao
