// Histogram CDF's tiles (HistogramTiles.h, HistogramChannels.cxx): whatever the plan (the
// thread count and the region decide it) and wherever rows of boxes hold one bin only
// (the shortcut that skips their column sums), the openness is the definition's, against a
// brute force (HistogramTestSupport.h).
#include "HistogramTestSupport.h"
#include "TestVolumes.h"

#include "vao/HistogramCdf.h"

#include <gtest/gtest.h>

#include <random>

using namespace vaotest;

namespace
{

/// A background of two values (100 above row 12, 300 from it, and 300 in the last slices)
/// around a block of random values: rows whose boxes hold one value, rows that hold the
/// block, and the switches between them.
std::vector<std::int16_t> backgroundWithBlock(const vao::Index3& d)
{
  std::mt19937 rng(11);
  std::uniform_int_distribution<int> value(-200, 600);
  std::vector<std::int16_t> v(static_cast<std::size_t>(d[0] * d[1] * d[2]));
  for (std::int64_t z = 0; z < d[2]; ++z)
    for (std::int64_t y = 0; y < d[1]; ++y)
      for (std::int64_t x = 0; x < d[0]; ++x)
      {
        const bool block = x >= 10 && x < 25 && y >= 8 && y < 20 && z >= 5 && z < 12;
        const std::int16_t background = y < 12 && z < d[2] - 4 ? 100 : 300;
        v[(z * d[1] + y) * d[0] + x] = block ? std::int16_t(value(rng)) : background;
      }
  return v;
}

} // namespace

TEST(HistogramCdfTiles, RowsOfOneBinGiveTheDefinition)
{
  const vao::Index3 dims = { 40, 30, 20 };
  const auto v = backgroundWithBlock(dims);
  std::vector<double> thresholds;
  ASSERT_TRUE(vao::volumeThresholds(viewOf(v, dims), 64, thresholds).ok);
  // 300 above the last threshold: a background in no bin.
  const std::vector<double> below300 = { 50, 120, 200 };
  for (const vao::Radius r : { vao::Radius{ 1, 1, 1 }, { 2, 3, 1 }, { 0, 2, 2 }, { 3, 0, 3 } })
    for (const int threads : { 1, 3 })
    {
      SCOPED_TRACE(testing::Message()
        << "radius " << r.x << "," << r.y << "," << r.z << ", threads " << threads);
      expectMatchesDefinition(v, dims, r, thresholds, vao::QueryMode::VoxelValue, 0.0, threads);
      expectMatchesDefinition(v, dims, r, thresholds, vao::QueryMode::IsoValue, 250.0, threads);
      expectMatchesDefinition(v, dims, r, below300, vao::QueryMode::VoxelValue, 0.0, threads);
      expectMatchesDefinition(v, dims, r, below300, vao::QueryMode::IsoValue, 100.0, threads);
    }
}

TEST(HistogramCdfTiles, EveryPlanGivesTheSameNumbers)
{
  // Thread counts change the tiles and the z-ranges; a region changes them again.
  const vao::Index3 dims = { 70, 45, 33 };
  auto v = randomVolume<float>(dims, -50.0, 80.0, 21);
  const auto block = backgroundWithBlock(dims);
  for (std::size_t i = 0; i < v.size(); i += 2)
    v[i] = block[i]; // half of the voxels from the background and block
  const auto view = viewOf(v, dims);
  std::vector<double> thresholds;
  ASSERT_TRUE(vao::volumeThresholds(view, 64, thresholds).ok);
  const vao::Radius r{ 4, 2, 3 };
  const vao::Region region{ { 3, 4, 2 }, { 60, 37, 29 } };
  const auto one = histogramOpenness(view, region, r, thresholds, vao::QueryMode::VoxelValue, 0, 1);
  for (const int threads : { 2, 3, 5, 8, 16 })
    EXPECT_EQ(
      histogramOpenness(view, region, r, thresholds, vao::QueryMode::VoxelValue, 0, threads), one)
      << threads << " threads";
  expectMatchesDefinition(v, dims, r, thresholds, vao::QueryMode::VoxelValue, 0.0, 7);
}
