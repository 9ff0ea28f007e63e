// A level of the moment pyramid prepared for many trilinear samples. The surface queries
// sample every point's levels tens of times (the shadow march), so the divisions, bounds
// and strides are done once here, and kLanes points are sampled together: their loads are
// independent, so the processor overlaps them. This is the definition of a lane's sample;
// SurfaceLanes.h has the AVX2 form and the dispatch.
#pragma once

#include "vao/Estimators.h"
#include "vao/VarianceOcclusionMap.h"

#include <algorithm>
#include <cstdint>
#include <limits>
#include <vector>

namespace vao
{
namespace detail
{

/// Points a surface query samples together. (16 rather than 8: the march then has
/// independent vectors whose loads overlap, in AVX-512 and in AVX2.)
constexpr int kLanes = 16;

/// The numbers of one level that its samples read.
struct LevelGrid
{
  const float* mean = nullptr;
  const float* variance = nullptr;
  double origin[3] = { 0, 0, 0 };
  double inverseSpacing[3] = { 1, 1, 1 };
  double maxIndex[3] = { 0, 0, 0 };     // dims - 1
  std::int64_t stride[3] = { 1, 0, 0 }; // 1, nx, nx ny
  double roundingVariance = 0.0;        // of the level's moments (the estimators' flat rule)
  double roundingSpread = 0.0;          // flatRoundingSpread(roundingVariance)
  // Voxel indices fit in 32 bits: the AVX2 lanes' gathers apply (else the plain loop).
  bool narrowIndices = true;
  // At least two voxels along x: a cell's two x corners are one 8-byte load.
  bool pairedRows = false;
  // Optional: the CellBounds below.
  const float* cellBounds = nullptr;
  // Tiled (LevelTiles.h): the cell whose lower corner is (i, j, k) lies in tile
  // t = sum over the axes of (c >> 3) * tileStride[a], c its coordinate, and its lower
  // corner at tileOffsets[t] + sum of (c & 7) * stride[a]; its other corners follow with
  // the strides, in the same tile. The variance follows its mean (variance = mean + 1,
  // the strides in floats).
  bool tiled = false;
  std::int64_t tileStride[3] = { 0, 0, 0 };
  const std::int32_t* tileOffsets = nullptr;

  LevelGrid() = default;
  explicit LevelGrid(const MomentLevel& level)
    : mean(level.mean.data())
    , variance(level.variance.data())
    , roundingVariance(level.roundingVariance)
    , roundingSpread(flatRoundingSpread(level.roundingVariance))
  {
    for (int a = 0; a < 3; ++a)
    {
      this->origin[a] = level.origin[a];
      this->inverseSpacing[a] = 1.0 / level.spacing[a];
      this->maxIndex[a] = static_cast<double>(level.dims[a] - 1);
    }
    this->stride[1] = level.dims[0];
    this->stride[2] = level.dims[0] * level.dims[1];
    this->narrowIndices =
      this->stride[2] * level.dims[2] <= std::numeric_limits<std::int32_t>::max();
    this->pairedRows = level.dims[0] >= 2;
  }
};

/// The largest mean and variance (at least 0) of the corners of every cell of a level, as
/// float pairs indexed like the level's voxels (cell = its lower corner). A trilinear sample
/// blends its cell's corners, so it lies below both; the Chebyshev occlusion of a query
/// above that mean is then at most var / (var + (q - mean)^2). The shadow march passes over
/// a sample whose bound cannot raise its occlusion.
class CellBounds
{
public:
  /// Builds the bounds of `level` and points `grid` at them.
  CellBounds(const MomentLevel& level, LevelGrid& grid)
    : pairs(2 * level.mean.size())
  {
    const std::int64_t n = static_cast<std::int64_t>(level.mean.size());
    for (std::int64_t i = 0; i < n; ++i)
    {
      this->pairs[2 * i] = level.mean[i];
      this->pairs[2 * i + 1] = std::max(0.0f, level.variance[i]);
    }
    // Separable: each voxel takes the maximum of itself and its upper neighbour (where
    // there is one) along x, then y, then z.
    const std::int64_t nx = level.dims[0], ny = level.dims[1], nz = level.dims[2];
    auto take = [this](std::int64_t i, std::int64_t j)
    {
      this->pairs[2 * i] = std::max(this->pairs[2 * i], this->pairs[2 * j]);
      this->pairs[2 * i + 1] = std::max(this->pairs[2 * i + 1], this->pairs[2 * j + 1]);
    };
    for (std::int64_t line = 0; line < ny * nz; ++line)
      for (std::int64_t x = 0; x + 1 < nx; ++x)
        take(line * nx + x, line * nx + x + 1);
    for (std::int64_t z = 0; z < nz; ++z)
      for (std::int64_t y = 0; y + 1 < ny; ++y)
        for (std::int64_t x = 0; x < nx; ++x)
          take((z * ny + y) * nx + x, (z * ny + y + 1) * nx + x);
    for (std::int64_t i = 0; i < nx * ny * (nz - 1); ++i)
      take(i, i + nx * ny);
    grid.cellBounds = this->pairs.data();
  }

private:
  std::vector<float> pairs;
};

/// Trilinear mean and variance (clamped at 0) of the level at world (x, y, z), clamped to
/// the level's bounds: the cell's lower corner, the fractions towards the upper one, and
/// nested lerps along x, y, z.
inline void trilinearSample(
  const LevelGrid& g, double x, double y, double z, double& mean, double& variance)
{
  using IndexT = std::int64_t;
  const double p[3] = { x, y, z };
  IndexT base = 0, tile = 0;
  IndexT step[3];
  double f[3];
  for (int a = 0; a < 3; ++a)
  {
    const double u =
      std::min(std::max((p[a] - g.origin[a]) * g.inverseSpacing[a], 0.0), g.maxIndex[a]);
    const IndexT lower = static_cast<IndexT>(u); // u >= 0: truncation is the floor
    f[a] = u - static_cast<double>(lower);
    if (g.tiled)
    {
      tile += (lower >> 3) * g.tileStride[a];
      base += (lower & 7) * g.stride[a];
    }
    else
    {
      base += lower * g.stride[a];
    }
    step[a] = u < g.maxIndex[a] ? g.stride[a] : IndexT(0); // upper corner, clamped
  }
  if (g.tiled)
    base += g.tileOffsets[tile];
  auto blend = [&](const float* c)
  {
    auto lerp = [](double a, double b, double t) { return a + t * (b - a); };
    auto row = [&](IndexT i) { return lerp(c[i], c[i + step[0]], f[0]); };
    const double lowerPlane = lerp(row(base), row(base + step[1]), f[1]);
    const double upperPlane = lerp(row(base + step[2]), row(base + step[2] + step[1]), f[1]);
    return lerp(lowerPlane, upperPlane, f[2]);
  };
  mean = blend(g.mean);
  variance = std::max(0.0, blend(g.variance));
}

/// occlusion[k] = 1 - the estimator's openness of query[k] at world (x[k], y[k], z[k]) of
/// one level, for the kLanes lanes: the definition, and the path without AVX2.
inline void occlusionLanesPlain(const LevelGrid& g, Method estimator, const double* x,
  const double* y, const double* z, const double* query, double* occlusion)
{
  for (int k = 0; k < kLanes; ++k)
  {
    double mean, variance;
    trilinearSample(g, x[k], y[k], z[k], mean, variance);
    occlusion[k] = 1.0 -
      (estimator == Method::Chebyshev
          ? opennessChebyshevWithin(query[k], mean, variance, g.roundingVariance, g.roundingSpread)
          : opennessFromStats(estimator, query[k],
              { mean, variance, mean, mean, g.roundingVariance }, ErfMode::Exact));
  }
}

} // namespace detail
} // namespace vao
