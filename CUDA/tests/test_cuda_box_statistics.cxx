// The CUDA backend's box statistics against the CPU's: every radius 0..12 on odd-sized
// volumes, anisotropic radii and radii larger than the volume, sub-regions, a strided
// component, and only the outputs asked for. Each test skips where there is no device.
#include "CudaTestSupport.h"

using namespace vaotest;

namespace
{

// ---------------------------------------------------------------------------------------
// Box statistics.

TEST(CudaBoxStatistics, EveryRadiusZeroToTwelveOnOddVolumes)
{
  VAO_REQUIRE_CUDA_DEVICE();
  const vao::Index3 dims = { 41, 29, 17 };
  const auto v8 = randomVolume<std::uint8_t>(dims, 0, 6, 101); // few values: ties, flat boxes
  const auto v16 = randomVolume<std::int16_t>(dims, -1024, 1600, 102);
  const auto vf = randomVolume<float>(dims, -1, 1, 103);
  for (int r = 0; r <= 12; ++r)
  {
    const vao::Radius radius{ r, r, r };
    expectStatsMatchCpu(viewOf(v8, dims), vao::Region::whole(viewOf(v8, dims)), radius);
    expectStatsMatchCpu(viewOf(v16, dims), vao::Region::whole(viewOf(v16, dims)), radius);
    expectStatsMatchCpu(viewOf(vf, dims), vao::Region::whole(viewOf(vf, dims)), radius);
  }
  const vao::Index3 other = { 37, 23, 19 };
  const auto w16 = randomVolume<std::int16_t>(other, -1024, 3000, 104);
  for (int r : { 0, 1, 5, 10, 12 })
  {
    expectStatsMatchCpu(viewOf(w16, other), vao::Region::whole(viewOf(w16, other)), { r, r, r });
  }
}

TEST(CudaBoxStatistics, AnisotropicRadiiAndRadiiLargerThanTheVolume)
{
  VAO_REQUIRE_CUDA_DEVICE();
  const vao::Index3 dims = { 37, 23, 19 };
  const auto v16 = randomVolume<std::int16_t>(dims, -1024, 1600, 111);
  const auto vf = randomVolume<float>(dims, -3, 5, 112);
  const auto vd = randomVolume<double>(dims, 1e6, 1e6 + 10, 113); // large offset, small spread
  const auto v32 = randomVolume<std::int32_t>(dims, -200000, 200000, 114);
  const auto v8 = randomVolume<std::uint8_t>(dims, 0, 255, 115);
  const vao::Radius radii[] = { { 1, 4, 0 }, { 7, 2, 3 }, { 12, 0, 5 }, { 0, 0, 9 }, { 40, 3, 2 },
    { 2, 30, 25 }, { 60, 60, 60 } };
  for (const auto& r : radii)
  {
    expectStatsMatchCpu(viewOf(v16, dims), vao::Region::whole(viewOf(v16, dims)), r);
    expectStatsMatchCpu(viewOf(vf, dims), vao::Region::whole(viewOf(vf, dims)), r);
    expectStatsMatchCpu(viewOf(v8, dims), vao::Region::whole(viewOf(v8, dims)), r);
  }
  expectStatsMatchCpu(viewOf(vd, dims), vao::Region::whole(viewOf(vd, dims)), { 7, 2, 3 });
  expectStatsMatchCpu(viewOf(vd, dims), vao::Region::whole(viewOf(vd, dims)), { 60, 60, 60 });
  expectStatsMatchCpu(viewOf(v32, dims), vao::Region::whole(viewOf(v32, dims)), { 12, 0, 5 });
  expectStatsMatchCpu(viewOf(v32, dims), vao::Region::whole(viewOf(v32, dims)), { 3, 3, 3 });
}

TEST(CudaBoxStatistics, SubRegions)
{
  VAO_REQUIRE_CUDA_DEVICE();
  const vao::Index3 dims = { 41, 29, 17 };
  const auto v16 = randomVolume<std::int16_t>(dims, -1000, 1500, 121);
  const auto vf = randomVolume<float>(dims, -1, 1, 122);
  const vao::Region regions[] = {
    { { 3, 2, 5 }, { 9, 7, 11 } },   // interior block
    { { 0, 28, 0 }, { 41, 1, 17 } }, // one row plane at the far y face
    { { 40, 0, 16 }, { 1, 29, 1 } }, // one column at the far x/z corner
    { { 5, 0, 0 }, { 30, 29, 17 } }, // x-trimmed slab
    { { 0, 0, 9 }, { 41, 29, 8 } },  // z-upper half (a distributed piece)
  };
  for (const auto& region : regions)
  {
    expectStatsMatchCpu(viewOf(v16, dims), region, { 4, 2, 3 });
    expectStatsMatchCpu(viewOf(vf, dims), region, { 10, 10, 10 });
    expectStatsMatchCpu(viewOf(vf, dims), region, { 0, 6, 1 });
  }
}

TEST(CudaBoxStatistics, ReadsOneComponentThroughTheStride)
{
  VAO_REQUIRE_CUDA_DEVICE();
  const vao::Index3 dims = { 23, 17, 13 };
  const auto scalar = randomVolume<std::int16_t>(dims, -1000, 1000, 131);
  std::vector<std::int16_t> interleaved(scalar.size() * 3, std::int16_t(32000));
  for (std::size_t i = 0; i < scalar.size(); ++i)
  {
    interleaved[3 * i + 1] = scalar[i];
  }
  vao::VolumeView strided = viewOf(interleaved, dims, 3);
  strided.data = interleaved.data() + 1;
  const auto whole = vao::Region::whole(strided);
  const vao::Region part{ { 2, 3, 4 }, { 15, 9, 7 } };
  for (const vao::Radius& r : { vao::Radius{ 2, 3, 1 }, vao::Radius{ 6, 6, 6 } })
  {
    expectStatsMatchCpu(strided, whole, r);
    expectStatsMatchCpu(strided, part, r);
    // The strided GPU result equals the contiguous CPU result (the other components unread).
    StatsArrays contiguous(whole.voxelCount(), 0.0), gpu(whole.voxelCount(), 0.0);
    ASSERT_TRUE(vao::computeBoxStatistics(viewOf(scalar, dims), whole, r, contiguous.output()).ok);
    const vao::Status status = vao::cuda::computeBoxStatistics(strided, whole, r, gpu.output());
    ASSERT_TRUE(status.ok) << status.message;
    EXPECT_EQ(gpu.minimum, contiguous.minimum);
    EXPECT_EQ(gpu.maximum, contiguous.maximum);
    EXPECT_EQ(gpu.count, contiguous.count);
  }
}

TEST(CudaBoxStatistics, WritesOnlyTheRequestedOutputs)
{
  VAO_REQUIRE_CUDA_DEVICE();
  const vao::Index3 dims = { 19, 11, 7 };
  const auto v = randomVolume<float>(dims, -2, 2, 141);
  const auto view = viewOf(v, dims);
  const auto whole = vao::Region::whole(view);
  const vao::Radius r{ 3, 2, 1 };
  StatsArrays cpu(whole.voxelCount(), 0.0), gpu(whole.voxelCount(), -9.0);
  ASSERT_TRUE(vao::computeBoxStatistics(view, whole, r, cpu.output()).ok);
  // Only the mean and the maximum, then only the variance and the minimum.
  vao::BoxStatisticsOutput meanMax{ nullptr, gpu.mean.data(), nullptr, nullptr,
    gpu.maximum.data() };
  vao::Status status = vao::cuda::computeBoxStatistics(view, whole, r, meanMax);
  ASSERT_TRUE(status.ok) << status.message;
  vao::BoxStatisticsOutput varMin{ nullptr, nullptr, gpu.variance.data(), gpu.minimum.data(),
    nullptr };
  status = vao::cuda::computeBoxStatistics(view, whole, r, varMin);
  ASSERT_TRUE(status.ok) << status.message;
  std::int64_t failures = 0;
  for (std::int64_t k = 0; k < whole.voxelCount(); ++k)
  {
    const bool ok = gpu.count[k] == -9.0 && gpu.minimum[k] == cpu.minimum[k] &&
      gpu.maximum[k] == cpu.maximum[k] &&
      closeRelative(gpu.mean[k], cpu.mean[k], kStatsTolerance) &&
      closeRelative(gpu.variance[k], cpu.variance[k], kStatsTolerance);
    if (!ok && failures++ < 5)
    {
      ADD_FAILURE() << "voxel " << k << ": count " << gpu.count[k] << " (must stay -9), mean "
                    << gpu.mean[k] << " vs " << cpu.mean[k] << ", variance " << gpu.variance[k]
                    << " vs " << cpu.variance[k] << ", min " << gpu.minimum[k] << " vs "
                    << cpu.minimum[k] << ", max " << gpu.maximum[k] << " vs " << cpu.maximum[k];
    }
  }
  EXPECT_EQ(failures, 0);
}

} // namespace
