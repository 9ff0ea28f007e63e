// The checks both surface queries (SurfaceSampling.cxx) make before they sample: the
// pyramid and the levels used, the parameters, the points and normals (double, or float
// read in place), and somewhere to write.
#pragma once

#include "vao/VarianceOcclusionMap.h"

#include <cmath>
#include <cstdint>
#include <sstream>
#include <string>
#include <vector>

namespace vao
{
namespace detail
{

template <class P>
bool finite3(const P* p)
{
  return std::isfinite(p[0]) && std::isfinite(p[1]) && std::isfinite(p[2]);
}

inline std::string pointMessage(const char* what, std::int64_t i)
{
  std::ostringstream s;
  s << what << " " << i;
  return s.str();
}

/// Checks the pyramid and resolves the number of levels used.
/// `tiled`: the first levels of a SurfacePyramid, in tiles (LevelTiles.h), have no arrays.
inline Status checkPyramid(
  const std::vector<MomentLevel>& pyramid, int requested, int& levels, int tiled = 0)
{
  if (pyramid.empty())
  {
    return Status::failure("the moment pyramid is empty (build it with buildMomentPyramid)");
  }
  for (const MomentLevel& level : pyramid)
  {
    const std::int64_t n =
      &level - &pyramid[0] < tiled ? 0 : level.dims[0] * level.dims[1] * level.dims[2];
    if (level.dims[0] < 1 || level.dims[1] < 1 || level.dims[2] < 1 ||
      static_cast<std::int64_t>(level.mean.size()) != n ||
      static_cast<std::int64_t>(level.variance.size()) != n || !(level.kernelRadius > 0.0))
    {
      return Status::failure(
        "a level of the moment pyramid is inconsistent (dims, arrays or radius)");
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

inline Status checkParameters(const SurfaceOcclusionParameters& p)
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
  if (p.combination != LevelCombination::MaximumOcclusion &&
    p.combination != LevelCombination::Mean)
  {
    return Status::failure("unknown level combination");
  }
  return Status::success();
}

/// Validates points (finite) and normals (finite, non-zero).
template <class P>
Status checkPoints(const P* points, const P* normals, std::int64_t count)
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
    const P* nn = normals + 3 * i;
    if (!finite3(nn))
    {
      return Status::failure(pointMessage("non-finite normal at point", i));
    }
    const double a = nn[0], b = nn[1], c = nn[2]; // float normals as PointLanes reads them
    if (!(a * a + b * b + c * c > 0.0))
    {
      return Status::failure(pointMessage("zero normal at point", i));
    }
  }
  return Status::success();
}

/// The checks both surface queries share: the pyramid and the levels used, the
/// parameters, the points and normals, and somewhere to write.
template <class P>
Status checkQuery(const std::vector<MomentLevel>& pyramid,
  const SurfaceOcclusionParameters& parameters, const P* points, const P* normals,
  std::int64_t count, const float* out, int& levels, int tiled = 0)
{
  Status status = checkPyramid(pyramid, parameters.levels, levels, tiled);
  if (status.ok)
    status = checkParameters(parameters);
  if (status.ok)
    status = checkPoints(points, normals, count);
  if (status.ok && count > 0 && !out)
    status = Status::failure("the output array must not be null");
  return status;
}

} // namespace detail
} // namespace vao
