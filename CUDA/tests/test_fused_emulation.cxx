// The device's fused statistics pass (src/cuda/common/FusedStatistics.h) and its slab
// schedule (src/cuda/common/SlabPlan.h) run on the host: the same block code as the GPU's, each
// phase as a loop, the chunks arriving in the schedule's order into poisoned device memory. They
// are checked against the separate passes (bit for bit where the sums are exact), against
// themselves with every phase run backwards, and across slab thicknesses; their checks
// against the CPU library are in test_pipeline_emulation.cxx, and test_cuda.cxx checks the
// real device where there is one.
#include "PipelineEmulation.h"
#include "ResultComparison.h"

#include "vao/AmbientOcclusion.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace vaotest;
using vao::gpu::Index;

namespace
{

const vao::gpu::EstimatorSetting kStatistics{ vao::Method::GaussianCdf, vao::QueryMode::VoxelValue,
  0, vao::ErfMode::Exact };

} // namespace

TEST(FusedPassOnHost, ExactSumsEqualTheSeparatePassesBitForBit)
{
  // Integer moments are exact in both, so every output must have the same bits.
  const vao::Index3 dims = { 45, 21, 30 };
  const auto i16 = randomVolume<std::int16_t>(dims, -1024, 3000, 19);
  const vao::Region region{ { 2, 1, 3 }, { 40, 19, 26 } };
  for (const vao::Radius& r :
    { vao::Radius{ 3, 3, 3 }, vao::Radius{ 10, 10, 10 }, vao::Radius{ 1, 6, 2 } })
  {
    const vao::gpu::EstimatorSetting gaussian{ vao::Method::GaussianCdf, vao::QueryMode::VoxelValue,
      0, vao::ErfMode::Exact };
    const Results passes = emulate(i16, dims, region, r, false, gaussian);
    const Results fused = emulate(i16, dims, region, r, false, gaussian, { true, 0, false });
    EXPECT_TRUE(sameBits(passes.openness, fused.openness));
    EXPECT_TRUE(sameBits(passes.variance, fused.variance));
    const Results statsPasses = emulate(i16, dims, region, r, true, kStatistics);
    const Results statsFused = emulate(i16, dims, region, r, true, kStatistics, { true, 0, false });
    EXPECT_TRUE(sameBits(statsPasses.count, statsFused.count));
    EXPECT_TRUE(sameBits(statsPasses.mean, statsFused.mean));
    EXPECT_TRUE(sameBits(statsPasses.varianceD, statsFused.varianceD));
  }
}

TEST(FusedPassOnHost, NoPhaseDependsOnTheOrderOfItsItemsOrOnTheSlabs)
{
  const vao::Index3 dims = { 40, 20, 50 };
  const auto f32 = randomVolume<float>(dims, -3, 7, 20);
  const vao::Region region{ { 1, 2, 4 }, { 38, 17, 43 } };
  const vao::gpu::EstimatorSetting gaussian{ vao::Method::GaussianCdf, vao::QueryMode::VoxelValue,
    0, vao::ErfMode::Exact };
  for (const vao::Radius& r : { vao::Radius{ 2, 2, 2 }, vao::Radius{ 5, 1, 7 } })
  {
    const Results forwards = emulate(f32, dims, region, r, false, gaussian, { true, 0, false });
    const Results backwards = emulate(f32, dims, region, r, false, gaussian, { true, 0, true });
    EXPECT_TRUE(sameBits(forwards.openness, backwards.openness));
    EXPECT_TRUE(sameBits(forwards.variance, backwards.variance));
    // Thin slabs: each starts its own segments, so the float sums may round otherwise,
    // but each slab must find its chunks uploaded.
    for (Index slices : { 1, 3, 7, 100 })
    {
      SCOPED_TRACE(slices);
      const Results slabs = emulate(f32, dims, region, r, false, gaussian, { true, slices, false });
      for (size_t k = 0; k < forwards.openness.size(); ++k)
      {
        ASSERT_NEAR(slabs.openness[k], forwards.openness[k], 1e-6) << k;
        ASSERT_NEAR(
          slabs.variance[k], forwards.variance[k], 1e-6 * std::max(1.0f, forwards.variance[k]))
          << k;
      }
    }
  }
}

TEST(FusedPassOnHost, SlabPlanUploadsEachSliceOnceBeforeItIsRead)
{
  const vao::Index3 dims = { 8, 8, 97 };
  for (const vao::Region& region : { vao::Region{ { 0, 0, 0 }, dims },
         vao::Region{ { 0, 0, 10 }, { 8, 8, 50 } }, vao::Region{ { 0, 0, 96 }, { 8, 8, 1 } } })
    for (int rz : { 0, 1, 4, 30, 200 })
      for (Index slices : { Index(1), Index(5), Index(32), Index(1000) })
      {
        const auto g = vao::gpu::geometryFor(dims, region, { 1, 1, rz });
        const auto plan = vao::gpu::planSlabs(g, slices);
        ASSERT_FALSE(plan.empty());
        Index slice = 0, chunk = 0;
        for (const auto& step : plan)
        {
          EXPECT_EQ(step.sliceBegin, slice);
          EXPECT_GT(step.sliceEnd, step.sliceBegin);
          EXPECT_LE(step.sliceEnd - step.sliceBegin, slices);
          EXPECT_EQ(step.chunkBegin, chunk);
          // Everything the slab's last window reads is up.
          EXPECT_GE(step.chunkEnd, std::min<Index>(g.sz, g.oz + step.sliceEnd + rz));
          slice = step.sliceEnd;
          chunk = step.chunkEnd;
        }
        EXPECT_EQ(slice, g.rz);
        EXPECT_EQ(chunk, g.sz);
      }
  // About four slabs, each at least two segments.
  const auto g =
    vao::gpu::geometryFor({ 256, 256, 415 }, { { 0, 0, 0 }, { 256, 256, 415 } }, { 10, 10, 10 });
  EXPECT_EQ(
    vao::gpu::planSlabs(g, vao::gpu::slabSlices(g, vao::gpu::segmentLength(10))).size(), 4u);
}

TEST(FusedPassOnHost, SharedMemoryFitsTheDeviceForCommonRadii)
{
  // An H100 grants a block 227 KiB: R = 10 fits with the extrema of 16-bit and 32-bit
  // data; those of doubles, and x-y radii of 43, take the separate passes.
  const auto g =
    vao::gpu::geometryFor({ 256, 256, 415 }, { { 0, 0, 0 }, { 256, 256, 415 } }, { 10, 10, 10 });
  EXPECT_TRUE((vao::gpu::fusedPassFits<std::int64_t, std::int16_t>(g, false, 48 * 1024)));
  EXPECT_TRUE((vao::gpu::fusedPassFits<std::int64_t, std::int16_t>(g, true, 227 * 1024)));
  EXPECT_TRUE((vao::gpu::fusedPassFits<double, float>(g, true, 227 * 1024)));
  EXPECT_FALSE((vao::gpu::fusedPassFits<double, double>(g, true, 227 * 1024)));
  const auto wide =
    vao::gpu::geometryFor({ 256, 256, 415 }, { { 0, 0, 0 }, { 256, 256, 415 } }, { 43, 43, 10 });
  EXPECT_FALSE((vao::gpu::fusedPassFits<double, float>(wide, false, 227 * 1024)));
  const auto below =
    vao::gpu::geometryFor({ 256, 256, 415 }, { { 0, 0, 0 }, { 256, 256, 415 } }, { 42, 42, 10 });
  EXPECT_TRUE((vao::gpu::fusedPassFits<double, float>(below, false, 227 * 1024)));
}

TEST(FusedPassOnHost, ExtremaEqualTheSeparatePassesForEveryRadius)
{
  // Minimum and maximum are exact in both: the same bits, through every edge clamp of the
  // tile, deque and slab.
  const vao::Index3 dims = { 45, 21, 37 };
  const auto i16 = randomVolume<std::int16_t>(dims, -1024, 3000, 21);
  const auto f32 = randomVolume<float>(dims, -2, 2, 22);
  const vao::Region region{ { 3, 0, 2 }, { 40, 21, 33 } };
  for (const vao::Radius& r :
    { vao::Radius{ 0, 0, 0 }, vao::Radius{ 1, 1, 1 }, vao::Radius{ 3, 2, 5 },
      vao::Radius{ 10, 10, 10 }, vao::Radius{ 0, 7, 20 }, vao::Radius{ 30, 0, 1 } })
    for (const Emulation& how :
      { Emulation{ true, 0, false }, Emulation{ true, 0, true }, Emulation{ true, 4, false } })
    {
      const Results passes = emulate(i16, dims, region, r, true, kStatistics);
      const Results fused = emulate(i16, dims, region, r, true, kStatistics, how);
      EXPECT_TRUE(sameBits(passes.minimum, fused.minimum));
      EXPECT_TRUE(sameBits(passes.maximum, fused.maximum));
      const Results floats = emulate(f32, dims, region, r, true, kStatistics);
      const Results floatsFused = emulate(f32, dims, region, r, true, kStatistics, how);
      EXPECT_TRUE(sameBits(floats.minimum, floatsFused.minimum));
      EXPECT_TRUE(sameBits(floats.maximum, floatsFused.maximum));
    }
  // Values rising along z keep every slice of a window in the minimum's deque, falling
  // ones in the maximum's: the deques at their fullest.
  std::vector<std::int16_t> rising(i16.size()), falling(i16.size());
  for (size_t i = 0; i < i16.size(); ++i)
  {
    const auto z = static_cast<int>(i / (dims[0] * dims[1]));
    rising[i] = static_cast<std::int16_t>(20 * z + i16[i] % 5);
    falling[i] = static_cast<std::int16_t>(-rising[i]);
  }
  for (const auto* v : { &rising, &falling })
    for (const vao::Radius& r : { vao::Radius{ 1, 1, 1 }, vao::Radius{ 2, 3, 6 } })
    {
      const Results passes = emulate(*v, dims, region, r, true, kStatistics);
      const Results fused = emulate(*v, dims, region, r, true, kStatistics, { true, 0, false });
      EXPECT_TRUE(sameBits(passes.minimum, fused.minimum));
      EXPECT_TRUE(sameBits(passes.maximum, fused.maximum));
    }
}
