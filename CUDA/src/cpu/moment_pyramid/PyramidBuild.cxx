// The moment pyramid of variance occlusion maps (Penner & Mitchell 2008;
// docs/methods.md, Penner and Mitchell).
//
// The blur itself, its precision and its windows: PyramidBlur.h.
#include "vao/Validation.h"
#include "vao/VarianceOcclusionMap.h"

#include "cpu/moment_pyramid/PyramidBlur.h"

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
  const bool firstDone = detail::dispatchScalarType(volume.type,
    [&](auto tag)
    {
      using T = decltype(tag);
      const RawSource<T> source{ detail::TypedVolume<T>(volume), shift };
      return blurDecimate(source, setup.firstStep, shift, result[0],
        detail::pyramidStageExecution(execution, 0, 0, levels), threads);
    });
  if (!firstDone)
  {
    return Status::cancelled();
  }
  if (!blurCoarserLevels(result, 1, shift, threads,
        [&](int l) { return detail::pyramidStageExecution(execution, l, l, levels); }))
  {
    return Status::cancelled();
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
  if (status.ok)
    status = checkPyramidSpan(scan);
  if (!status.ok)
  {
    return status;
  }
  setup.shift = dispatchScalarType(
    volume.type, [&](auto tag) { return sampledMean(TypedVolume<decltype(tag)>(volume)); });
  setup.roundingVariance = sumRoundingVariance(
    std::max(std::abs(scan.maximum - setup.shift), std::abs(scan.minimum - setup.shift)));
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
    level.kernelRadius =
      2.0 * std::max(level.spacing[0], std::max(level.spacing[1], level.spacing[2]));
    level.roundingVariance = setup.roundingVariance;
  }
}

} // namespace detail

double meanResolution(const MomentLevel& level)
{
  if (level.mean.size() == 0)
  {
    return 0.0;
  }
  const auto range = std::minmax_element(level.mean.data(), level.mean.data() + level.mean.size());
  const double lo = *range.first, hi = *range.second;
  const double halfUlp = std::ldexp(std::max(std::abs(lo), std::abs(hi)), -24);
  return hi > lo ? halfUlp / (hi - lo) : 0.0;
}

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
