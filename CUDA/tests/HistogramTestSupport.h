// Histogram CDF's openness through the public call, and its check against a brute force
// of the definition (ReferenceFormulas.h): the fraction of each clipped box at or below
// each threshold, counted voxel by voxel.
#pragma once

#include "ReferenceFormulas.h"
#include "TestVolumes.h"

#include "vao/AmbientOcclusion.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace vaotest
{

inline std::vector<float> histogramOpenness(const vao::VolumeView& view, const vao::Region& region,
  vao::Radius r, const std::vector<double>& thresholds,
  vao::QueryMode query = vao::QueryMode::VoxelValue, double iso = 0.0, int threads = 0)
{
  std::vector<float> out(region.voxelCount(), -1.0f);
  vao::AmbientOcclusionParameters p;
  p.method = vao::Method::HistogramCdf;
  p.radius = r;
  p.queryMode = query;
  p.isoValue = iso;
  p.thresholds = thresholds;
  vao::Execution execution;
  execution.threads = threads;
  const vao::Status status =
    vao::computeAmbientOcclusion(view, region, p, { out.data(), nullptr }, execution);
  EXPECT_TRUE(status.ok) << status.message;
  return out;
}

/// Fraction of the clipped box of (x, y, z) with v <= t, counted voxel by voxel.
template <class T>
double fractionAtOrBelow(const std::vector<T>& v, const vao::Index3& d, const vao::Radius& r,
  std::int64_t x, std::int64_t y, std::int64_t z, double t)
{
  double below = 0, total = 0;
  for (std::int64_t k = std::max<std::int64_t>(0, z - r.z); k <= std::min(d[2] - 1, z + r.z); ++k)
    for (std::int64_t j = std::max<std::int64_t>(0, y - r.y); j <= std::min(d[1] - 1, y + r.y); ++j)
      for (std::int64_t i = std::max<std::int64_t>(0, x - r.x); i <= std::min(d[0] - 1, x + r.x);
           ++i)
      {
        total += 1;
        below += static_cast<double>(v[(k * d[1] + j) * d[0] + i]) <= t ? 1 : 0;
      }
  return below / total;
}

template <class T>
void expectMatchesDefinition(const std::vector<T>& v, const vao::Index3& dims, vao::Radius r,
  const std::vector<double>& thresholds, vao::QueryMode query = vao::QueryMode::VoxelValue,
  double iso = 0.0, int threads = 0)
{
  const auto view = viewOf(v, dims);
  const auto got =
    histogramOpenness(view, vao::Region::whole(view), r, thresholds, query, iso, threads);
  std::int64_t k = 0, failures = 0;
  for (std::int64_t z = 0; z < dims[2]; ++z)
    for (std::int64_t y = 0; y < dims[1]; ++y)
      for (std::int64_t x = 0; x < dims[0]; ++x, ++k)
      {
        const double q = query == vao::QueryMode::IsoValue ? iso : static_cast<double>(v[k]);
        const double expected = reference::histogramCdf(
          q, thresholds, [&](double t) { return fractionAtOrBelow(v, dims, r, x, y, z, t); });
        if (!(std::abs(got[k] - expected) <= 2e-6) && failures++ < 8)
          ADD_FAILURE() << "(" << x << "," << y << "," << z << ") q " << q << ": " << got[k]
                        << " vs " << expected;
      }
  EXPECT_EQ(failures, 0);
}

} // namespace vaotest
