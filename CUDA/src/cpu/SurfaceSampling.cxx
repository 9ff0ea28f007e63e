// Surface ambient occlusion and soft shadows sampled from the moment pyramid (Penner &
// Mitchell 2008; the Penner & Mitchell section of METHODS.md).
#include "vao/VarianceOcclusionMap.h"
#include "vao/Validation.h"

#include "Parallel.h"
#include "VolumeAccess.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

namespace vao
{
namespace
{

bool finite3(const double* p)
{
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

std::string pointMessage(const char* what, std::int64_t i)
{
  std::ostringstream s;
  s << what << " " << i;
  return s.str();
}

/// Checks the pyramid and resolves the number of levels used.
Status checkPyramid(const std::vector<MomentLevel>& pyramid, int requested, int& levels)
{
  if (pyramid.empty())
  {
    return Status::failure("the moment pyramid is empty (build it with buildMomentPyramid)");
  }
  for (const MomentLevel& level : pyramid)
  {
    const std::int64_t n = level.dims[0] * level.dims[1] * level.dims[2];
    if (level.dims[0] < 1 || level.dims[1] < 1 || level.dims[2] < 1 ||
      static_cast<std::int64_t>(level.mean.size()) != n ||
      static_cast<std::int64_t>(level.variance.size()) != n || !(level.kernelRadius > 0.0))
    {
      return Status::failure("a level of the moment pyramid is inconsistent (dims, arrays or radius)");
    }
  }
  const int available = static_cast<int>(pyramid.size());
  if (requested == -1)
  {
    levels = available;
  }
  else if (requested < 1 || requested > available)
  {
    std::ostringstream s;
    s << "levels must be -1 (all) or in [1, " << available << "], got " << requested;
    return Status::failure(s.str());
  }
  else
  {
    levels = requested;
  }
  return Status::success();
}

Status checkParameters(const SurfaceOcclusionParameters& p)
{
  if (!std::isfinite(p.offsetFactor) || p.offsetFactor < 0.0)
  {
    return Status::failure("offsetFactor must be finite and >= 0");
  }
  if (p.query == SurfaceQuery::IsoValue && !std::isfinite(p.isoValue))
  {
    return Status::failure("isoValue must be finite");
  }
  if (p.query != SurfaceQuery::IsoValue && p.query != SurfaceQuery::HalfVoxelInside)
  {
    return Status::failure("unknown surface query mode");
  }
  if (p.estimator != Method::Chebyshev && p.estimator != Method::GaussianCdf)
  {
    return Status::failure("the surface estimator must be Chebyshev or Gaussian CDF");
  }
  if (p.combination != LevelCombination::MaximumOcclusion && p.combination != LevelCombination::Mean)
  {
    return Status::failure("unknown level combination");
  }
  return Status::success();
}

/// Validates points (finite) and normals (finite, non-zero).
Status checkPoints(const double* points, const double* normals, std::int64_t count)
{
  if (count < 0)
  {
    return Status::failure("the point count must be >= 0");
  }
  if (count > 0 && (!points || !normals))
  {
    return Status::failure("points and normals must not be null");
  }
  for (std::int64_t i = 0; i < count; ++i)
  {
    if (!finite3(points + 3 * i))
    {
      return Status::failure(pointMessage("non-finite coordinate at point", i));
    }
    const double* nn = normals + 3 * i;
    if (!finite3(nn))
    {
      return Status::failure(pointMessage("non-finite normal at point", i));
    }
    if (!(nn[0] * nn[0] + nn[1] * nn[1] + nn[2] * nn[2] > 0.0))
    {
      return Status::failure(pointMessage("zero normal at point", i));
    }
  }
  return Status::success();
}

std::array<double, 3> unit(const double* v)
{
  const double l = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return { v[0] / l, v[1] / l, v[2] / l };
}

/// The grid cell around a world position, clamped to the grid: lower and upper corner
/// indices and the fractions towards the upper one, per axis.
struct TrilinearCell
{
  std::int64_t i0[3], i1[3];
  double f[3];

  TrilinearCell(const Index3& dims, const std::array<double, 3>& origin, const std::array<double, 3>& spacing,
    const std::array<double, 3>& position)
  {
    for (int a = 0; a < 3; ++a)
    {
      const double maxIndex = static_cast<double>(dims[a] - 1);
      const double u = std::min(std::max((position[a] - origin[a]) / spacing[a], 0.0), maxIndex);
      const double fl = std::floor(u);
      i0[a] = static_cast<std::int64_t>(fl);
      i1[a] = std::min<std::int64_t>(i0[a] + 1, dims[a] - 1);
      f[a] = u - fl;
    }
  }
};

/// Trilinear value of the raw volume at a world position (clamped to its bounds).
template <class T>
double trilinear(const detail::TypedVolume<T>& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const std::array<double, 3>& position)
{
  const TrilinearCell cell(volume.dims, origin, spacing, position);
  const std::int64_t* i0 = cell.i0;
  const std::int64_t* i1 = cell.i1;
  const double* f = cell.f;
  auto v = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    return static_cast<double>(volume.value(x, y, z));
  };
  const double c00 = v(i0[0], i0[1], i0[2]) * (1 - f[0]) + v(i1[0], i0[1], i0[2]) * f[0];
  const double c10 = v(i0[0], i1[1], i0[2]) * (1 - f[0]) + v(i1[0], i1[1], i0[2]) * f[0];
  const double c01 = v(i0[0], i0[1], i1[2]) * (1 - f[0]) + v(i1[0], i0[1], i1[2]) * f[0];
  const double c11 = v(i0[0], i1[1], i1[2]) * (1 - f[0]) + v(i1[0], i1[1], i1[2]) * f[0];
  const double c0 = c00 * (1 - f[1]) + c10 * f[1];
  const double c1 = c01 * (1 - f[1]) + c11 * f[1];
  return c0 * (1 - f[2]) + c1 * f[2];
}

double levelOcclusion(const MomentLevel& level, const std::array<double, 3>& position, double query,
  Method estimator)
{
  double mean = 0.0, variance = 0.0;
  sampleLevel(level, position, mean, variance);
  const NeighbourhoodStats stats{ mean, variance, mean, mean, level.roundingVariance };
  const double open = estimator == Method::GaussianCdf
    ? opennessGaussianCdf(query, stats, ErfMode::Exact)
    : opennessChebyshev(query, stats);
  return 1.0 - open;
}

bool insideBounds(const MomentLevel& level, const std::array<double, 3>& p)
{
  const bool window = std::isfinite(level.wholeBounds[0]);
  for (int a = 0; a < 3; ++a)
  {
    const double lo = window ? level.wholeBounds[2 * a] : level.origin[a];
    const double hi =
      window ? level.wholeBounds[2 * a + 1] : level.origin[a] + (level.dims[a] - 1) * level.spacing[a];
    if (p[a] < lo || p[a] > hi)
    {
      return false;
    }
  }
  return true;
}

} // namespace

double sampleVolume(const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const std::array<double, 3>& position)
{
  return detail::dispatchScalarType(volume.type, [&](auto tag) {
    using T = decltype(tag);
    return trilinear(detail::TypedVolume<T>(volume), origin, spacing, position);
  });
}

void sampleLevel(const MomentLevel& level, const std::array<double, 3>& position, double& mean, double& variance)
{
  const TrilinearCell cell(level.dims, level.origin, level.spacing, position);
  const std::int64_t* i0 = cell.i0;
  const std::int64_t* i1 = cell.i1;
  const double* f = cell.f;
  const std::int64_t nx = level.dims[0], ny = level.dims[1];
  double m = 0.0, v = 0.0;
  for (int c = 0; c < 8; ++c)
  {
    const std::int64_t x = (c & 1) ? i1[0] : i0[0];
    const std::int64_t y = (c & 2) ? i1[1] : i0[1];
    const std::int64_t z = (c & 4) ? i1[2] : i0[2];
    const double w = ((c & 1) ? f[0] : 1 - f[0]) * ((c & 2) ? f[1] : 1 - f[1]) *
      ((c & 4) ? f[2] : 1 - f[2]);
    const std::int64_t i = (z * ny + y) * nx + x;
    m += w * level.mean[i];
    v += w * level.variance[i];
  }
  mean = m;
  variance = std::max(0.0, v);
}

namespace
{

/// The checks both surface queries share: the pyramid and the levels used, the
/// parameters, the points and normals, and somewhere to write.
Status checkQuery(const std::vector<MomentLevel>& pyramid, const SurfaceOcclusionParameters& parameters,
  const double* points, const double* normals, std::int64_t count, const float* out, int& levels)
{
  Status status = checkPyramid(pyramid, parameters.levels, levels);
  if (status.ok)
    status = checkParameters(parameters);
  if (status.ok)
    status = checkPoints(points, normals, count);
  if (status.ok && count > 0 && !out)
    status = Status::failure("the output array must not be null");
  return status;
}

/// f(i) for every point i, on every thread, reporting progress every `batch` points.
/// Returns false when cancelled.
template <class PerPoint>
bool forEachPoint(std::int64_t count, int batch, const Execution& execution, PerPoint&& f)
{
  const int threads = detail::resolveThreadCount(execution.threads);
  const int chunks = static_cast<int>(std::min<std::int64_t>(std::max<std::int64_t>(count, 1), threads * 8));
  return detail::parallelFor(count, chunks, threads, execution,
    [&](std::int64_t begin, std::int64_t end, detail::ChunkProgress& progress) {
      for (std::int64_t i = begin; i < end; ++i)
      {
        f(i);
        if ((i - begin) % batch == batch - 1 && !progress.advance(batch))
        {
          return;
        }
      }
    });
}

/// The occlusion of one surface point p (unit outward normal n) from the levels used.
double pointOcclusion(const std::vector<MomentLevel>& pyramid, int levels, const double* p,
  const std::array<double, 3>& n, double query, const SurfaceOcclusionParameters& parameters)
{
  double combined = 0.0;
  for (int l = 0; l < levels; ++l)
  {
    const double offset = parameters.offsetFactor * pyramid[l].kernelRadius;
    const std::array<double, 3> at = { p[0] + offset * n[0], p[1] + offset * n[1], p[2] + offset * n[2] };
    const double occlusion = levelOcclusion(pyramid[l], at, query, parameters.estimator);
    combined = parameters.combination == LevelCombination::Mean ? combined + occlusion / levels
                                                                : std::max(combined, occlusion);
  }
  return combined;
}

/// The largest occlusion met by the march from `start` along the unit `light`.
double marchOcclusion(const std::vector<MomentLevel>& pyramid, int levels, const std::array<double, 3>& start,
  const std::array<double, 3>& light, double query, Method estimator)
{
  // Steps of half the level's radius: a blob of the level's size cannot fall between two.
  constexpr double kStepFraction = 0.5;
  constexpr int kMaxSteps = 1 << 16;
  const MomentLevel& base = pyramid[0];
  const double r0 = base.kernelRadius;
  double occlusion = 0.0;
  double t = 0.0;
  for (int s = 0; s < kMaxSteps; ++s)
  {
    const std::array<double, 3> at = { start[0] + t * light[0], start[1] + t * light[1], start[2] + t * light[2] };
    if (!insideBounds(base, at))
    {
      break;
    }
    const int l = std::min(levels - 1, std::max(0, static_cast<int>(std::floor(std::log2(1.0 + t / r0)))));
    occlusion = std::max(occlusion, levelOcclusion(pyramid[l], at, query, estimator));
    if (occlusion >= 0.999)
    {
      break;
    }
    t += kStepFraction * pyramid[l].kernelRadius;
  }
  return occlusion;
}

} // namespace

Status surfaceAmbientOcclusion(const std::vector<MomentLevel>& pyramid, const VolumeView& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing, const double* points,
  const double* normals, std::int64_t count, const SurfaceOcclusionParameters& parameters, float* out,
  const Execution& execution)
{
  int levels = 0;
  Status status = checkQuery(pyramid, parameters, points, normals, count, out, levels);
  const bool half = parameters.query == SurfaceQuery::HalfVoxelInside;
  if (status.ok && half)
  {
    status = checkVolume(volume);
    if (status.ok)
      status = checkSpacing(spacing, "the volume's spacing");
    if (status.ok)
      status = checkFinitePoint(origin, "the volume's origin");
    if (!status.ok)
      status.message = "the half-voxel-inside query needs the volume: " + status.message;
  }
  if (!status.ok)
  {
    return status;
  }
  const double h = std::min(spacing[0], std::min(spacing[1], spacing[2]));
  const bool finished = detail::dispatchScalarType(half ? volume.type : ScalarType::Float32, [&](auto tag) {
    const detail::TypedVolume<decltype(tag)> typed(half ? volume : VolumeView{});
    return forEachPoint(count, 1024, execution, [&](std::int64_t i) {
      const double* p = points + 3 * i;
      const std::array<double, 3> n = unit(normals + 3 * i);
      const double query = half
        ? trilinear(typed, origin, spacing, { p[0] - 0.5 * h * n[0], p[1] - 0.5 * h * n[1], p[2] - 0.5 * h * n[2] })
        : parameters.isoValue;
      out[i] = static_cast<float>(1.0 - clamp01(pointOcclusion(pyramid, levels, p, n, query, parameters)));
    });
  });
  return finished ? Status::success() : Status::cancelled();
}

Status surfaceShadow(const std::vector<MomentLevel>& pyramid, const double* points, const double* normals,
  std::int64_t count, const std::array<double, 3>& lightDirection, const SurfaceOcclusionParameters& parameters,
  float* out, const Execution& execution)
{
  int levels = 0;
  Status status = checkQuery(pyramid, parameters, points, normals, count, out, levels);
  if (status.ok)
    status = checkFinitePoint(lightDirection, "the light direction");
  if (!status.ok)
  {
    return status;
  }
  const double lightLength = std::sqrt(lightDirection[0] * lightDirection[0] +
    lightDirection[1] * lightDirection[1] + lightDirection[2] * lightDirection[2]);
  if (!(lightLength > 0.0))
  {
    return Status::failure("the light direction must not be zero");
  }
  const std::array<double, 3> light = { lightDirection[0] / lightLength, lightDirection[1] / lightLength,
    lightDirection[2] / lightLength };
  const MomentLevel& base = pyramid[0];
  const double r0 = base.kernelRadius;
  const double h = std::min(base.spacing[0], std::min(base.spacing[1], base.spacing[2]));
  const bool finished = forEachPoint(count, 256, execution, [&](std::int64_t i) {
    const double* p = points + 3 * i;
    const std::array<double, 3> n = unit(normals + 3 * i);
    double query = parameters.isoValue;
    if (parameters.query == SurfaceQuery::HalfVoxelInside)
    {
      // No raw volume here: level 0's (blurred) mean half a voxel inside.
      double variance = 0.0;
      sampleLevel(base, { p[0] - 0.5 * h * n[0], p[1] - 0.5 * h * n[1], p[2] - 0.5 * h * n[2] }, query, variance);
    }
    const std::array<double, 3> start = { p[0] + r0 * n[0], p[1] + r0 * n[1], p[2] + r0 * n[2] };
    out[i] = static_cast<float>(1.0 - clamp01(marchOcclusion(pyramid, levels, start, light, query, parameters.estimator)));
  });
  return finished ? Status::success() : Status::cancelled();
}

} // namespace vao
