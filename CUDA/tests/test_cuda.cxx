// The CUDA backend against the CPU functions (the reference): the same statistics and the
// same openness on random odd-sized volumes, every radius 0..12, anisotropic radii, radii
// larger than the volume, several scalar types, sub-regions and a strided component.
//
// Every test that needs a device first asks vao::cuda::deviceStatus() and skips, with the
// reason, where there is none; CudaBackend.ReportsItsStateWithoutCrashing runs everywhere.
#include "CudaTestSupport.h"

#include "cpu/common/Parallel.h"

#include "vao/HistogramCdf.h"

using namespace vaotest;

namespace
{

// ---------------------------------------------------------------------------------------
// Runs on every machine: no device, no CUDA build, or a device.

TEST(CudaBackend, ReportsItsStateWithoutCrashing)
{
  const vao::cuda::DeviceStatus device = vao::cuda::deviceStatus();
  EXPECT_FALSE(device.description.empty())
    << "deviceStatus() should name the device or say why there is none";
  if (!vao::cuda::built())
  {
    EXPECT_FALSE(device.available) << "a build without CUDA cannot have a device";
  }
  const vao::Index3 dims = { 6, 5, 4 };
  const auto v = randomVolume<float>(dims, 0, 1, 3);
  const auto view = viewOf(v, dims);
  const auto whole = vao::Region::whole(view);
  StatsArrays stats(whole.voxelCount(), 0.0);
  std::vector<float> open(whole.voxelCount(), 0.0f);
  vao::AmbientOcclusionParameters p;
  p.radius = { 1, 1, 1 };
  vao::cuda::Timing timing;
  const vao::Status statsStatus =
    vao::cuda::computeBoxStatistics(view, whole, p.radius, stats.output(), {}, &timing);
  const vao::Status aoStatus =
    vao::cuda::computeAmbientOcclusion(view, whole, p, { open.data(), nullptr }, {}, &timing);
  if (device.available)
  {
    EXPECT_TRUE(statsStatus.ok) << statsStatus.message;
    EXPECT_TRUE(aoStatus.ok) << aoStatus.message;
    EXPECT_GT(vao::cuda::measureCopyBandwidth(1 << 24), 0.0);
  }
  else
  {
    EXPECT_FALSE(statsStatus.ok);
    EXPECT_FALSE(statsStatus.message.empty()) << "a failure without a device must say why";
    EXPECT_FALSE(aoStatus.ok);
    EXPECT_FALSE(aoStatus.message.empty()) << "a failure without a device must say why";
    EXPECT_TRUE(statsStatus.deviceFailure && aoStatus.deviceFailure)
      << "no device is a device failure: the CPU may still compute it";
    EXPECT_EQ(vao::cuda::measureCopyBandwidth(1 << 24), 0.0);
    std::cout << "[          ] built() = " << vao::cuda::built()
              << ", no device: " << device.description
              << "\n[          ] computeBoxStatistics says: " << statsStatus.message << std::endl;
  }
}

TEST(CudaBackend, EachRankTakesItsNodeLocalRankModuloTheDevices)
{
  using vao::cuda::chooseDevice;
  EXPECT_EQ(chooseDevice(-1, 4, 0), 0);
  EXPECT_EQ(chooseDevice(-1, 4, 3), 3);
  EXPECT_EQ(chooseDevice(-1, 4, 6), 2); // ranks 2 and 6 of a node with 4 devices share one
  EXPECT_EQ(chooseDevice(-1, 1, 5), 0);
  EXPECT_EQ(chooseDevice(-1, 3, -7), 0); // no sensible rank: the first device
  EXPECT_EQ(chooseDevice(2, 4, 3), 2);   // an explicit device wins over the rank
  EXPECT_EQ(chooseDevice(4, 4, 0), -1);  // not visible
  EXPECT_EQ(chooseDevice(-1, 0, 0), -1); // no device at all
  EXPECT_EQ(chooseDevice(0, 0, 0), -1);

  // The launchers' node-local rank, first of the variables that holds one.
  const char* names[] = { "OMPI_COMM_WORLD_LOCAL_RANK", "MPI_LOCALRANKID",
    "MV2_COMM_WORLD_LOCAL_RANK", "SLURM_LOCALID" };
  std::vector<std::pair<std::string, std::string>> saved;
  for (const char* name : names)
  {
    if (const char* value = std::getenv(name))
      saved.emplace_back(name, value);
    unsetenv(name);
  }
  EXPECT_EQ(vao::detail::nodeLocalRank(), 0) << "outside MPI";
  setenv("SLURM_LOCALID", "5", 1);
  EXPECT_EQ(vao::detail::nodeLocalRank(), 5);
  setenv("MPI_LOCALRANKID", "3", 1);
  EXPECT_EQ(vao::detail::nodeLocalRank(), 3) << "MPICH's variable comes before Slurm's";
  setenv("OMPI_COMM_WORLD_LOCAL_RANK", "not a number", 1);
  EXPECT_EQ(vao::detail::nodeLocalRank(), 3) << "a value that is no number is skipped";
  setenv("OMPI_COMM_WORLD_LOCAL_RANK", "1", 1);
  EXPECT_EQ(vao::detail::nodeLocalRank(), 1);
  for (const char* name : names)
    unsetenv(name);
  for (const auto& [name, value] : saved)
    setenv(name.c_str(), value.c_str(), 1);

  // An index past the visible devices is refused with a reason, in every build.
  const vao::cuda::DeviceStatus far = vao::cuda::deviceStatus(1 << 20);
  EXPECT_FALSE(far.available);
  EXPECT_EQ(far.index, -1);
  EXPECT_FALSE(far.description.empty());
  vao::Execution execution;
  execution.device = 1 << 20;
  const vao::Index3 dims = { 6, 5, 4 };
  const auto v = randomVolume<float>(dims, 0, 1, 3);
  std::vector<float> open(static_cast<size_t>(dims[0] * dims[1] * dims[2]));
  const vao::Status status = vao::cuda::computeAmbientOcclusion(
    viewOf(v, dims), vao::Region::whole(viewOf(v, dims)), {}, { open.data(), nullptr }, execution);
  EXPECT_FALSE(status.ok);
  EXPECT_TRUE(status.deviceFailure)
    << "a device that is not there is a device failure: the CPU may run";
}

TEST(CudaBackend, AnInjectedFailureIsADeviceFailureOfOneCall)
{
  VAO_REQUIRE_CUDA_DEVICE();
  const vao::Index3 dims = { 20, 18, 16 };
  const auto v = randomVolume<std::int16_t>(dims, -1000, 1000, 31);
  const auto view = viewOf(v, dims);
  std::vector<float> open(static_cast<size_t>(view.voxelCount()));
  vao::AmbientOcclusionParameters p;
  p.radius = { 2, 2, 2 };
  vao::cuda::injectDeviceFailures(2);
  for (vao::Method method : { vao::Method::GaussianCdf, vao::Method::ExactBox })
  {
    p.method = method;
    const vao::Status failed = vao::cuda::computeAmbientOcclusion(
      view, vao::Region::whole(view), p, { open.data(), nullptr });
    EXPECT_FALSE(failed.ok);
    EXPECT_TRUE(failed.deviceFailure);
    EXPECT_NE(failed.message.find("injected"), std::string::npos) << failed.message;
  }
  const vao::Status next =
    vao::cuda::computeAmbientOcclusion(view, vao::Region::whole(view), p, { open.data(), nullptr });
  EXPECT_TRUE(next.ok) << "the device works again after the injected failures: " << next.message;
}

TEST(CudaPyramid, EqualsTheCpuLevelByLevel)
{
  VAO_REQUIRE_CUDA_DEVICE();
  const vao::Index3 dims = { 67, 45, 39 };
  const auto v = randomVolume<std::int16_t>(dims, -1024, 2000, 41);
  const std::array<double, 3> origin = { 1.0, -2.0, 3.0 }, spacing = { 0.5, 0.5, 1.25 };
  for (const vao::PyramidParameters parameters :
    { vao::PyramidParameters{ 4, false }, vao::PyramidParameters{ 3, true } })
  {
    std::vector<vao::MomentLevel> cpu, gpu;
    ASSERT_TRUE(vao::buildMomentPyramid(viewOf(v, dims), origin, spacing, parameters, cpu).ok);
    const vao::Status status =
      vao::cuda::buildMomentPyramid(viewOf(v, dims), origin, spacing, parameters, gpu);
    ASSERT_TRUE(status.ok) << status.message;
    ASSERT_EQ(gpu.size(), cpu.size());
    for (size_t l = 0; l < cpu.size(); ++l)
    {
      ASSERT_EQ(gpu[l].dims, cpu[l].dims);
      EXPECT_EQ(gpu[l].spacing, cpu[l].spacing);
      for (size_t i = 0; i < cpu[l].mean.size(); ++i)
      {
        ASSERT_NEAR(
          gpu[l].mean[i], cpu[l].mean[i], 1e-5 * std::max(1.0f, std::abs(cpu[l].mean[i])));
        ASSERT_NEAR(
          gpu[l].variance[i], cpu[l].variance[i], 1e-5 * std::max(1.0f, cpu[l].variance[i]));
      }
    }
  }
  std::vector<vao::MomentLevel> bad = { vao::MomentLevel{} };
  const vao::Status rejected =
    vao::cuda::buildMomentPyramid(viewOf(v, dims), origin, { 0.5, 0.0, 1.0 }, {}, bad);
  EXPECT_FALSE(rejected.ok);
  EXPECT_FALSE(rejected.deviceFailure) << "a zero spacing is bad input, as on the CPU";
  EXPECT_TRUE(bad.empty());
}

// ---------------------------------------------------------------------------------------
// Openness.

TEST(CudaAmbientOcclusion, EverySeparableMethodEveryRadiusZeroToTwelve)
{
  VAO_REQUIRE_CUDA_DEVICE();
  const vao::Index3 dims = { 41, 29, 17 };
  const auto v8 = randomVolume<std::uint8_t>(dims, 0, 6, 201); // iso 3 equals voxel values
  const auto v16 = randomVolume<std::int16_t>(dims, -1024, 1600, 202);
  const auto vf = randomVolume<float>(dims, -1, 1, 203);
  for (int r = 0; r <= 12; ++r)
  {
    const vao::Radius radius{ r, r, r };
    expectEveryMethodMatchesCpu(
      viewOf(v8, dims), vao::Region::whole(viewOf(v8, dims)), radius, 3.0);
    expectEveryMethodMatchesCpu(
      viewOf(v16, dims), vao::Region::whole(viewOf(v16, dims)), radius, 100.0);
    expectEveryMethodMatchesCpu(
      viewOf(vf, dims), vao::Region::whole(viewOf(vf, dims)), radius, 0.25);
  }
}

TEST(CudaAmbientOcclusion, AnisotropicRadiiLargeRadiiAndOtherTypes)
{
  VAO_REQUIRE_CUDA_DEVICE();
  const vao::Index3 dims = { 37, 23, 19 };
  const auto v16 = randomVolume<std::int16_t>(dims, -1024, 1600, 211);
  const auto vf = randomVolume<float>(dims, -1, 1, 212);
  const auto vd = randomVolume<double>(dims, 1e6, 1e6 + 10, 213);
  const auto v32 = randomVolume<std::int32_t>(dims, -200000, 200000, 214);
  for (const vao::Radius& r : { vao::Radius{ 1, 4, 0 }, vao::Radius{ 7, 2, 3 },
         vao::Radius{ 12, 0, 5 }, vao::Radius{ 50, 50, 50 } })
  {
    expectEveryMethodMatchesCpu(viewOf(v16, dims), vao::Region::whole(viewOf(v16, dims)), r, 0.0);
    expectEveryMethodMatchesCpu(viewOf(vf, dims), vao::Region::whole(viewOf(vf, dims)), r, -0.5);
  }
  expectEveryMethodMatchesCpu(
    viewOf(vd, dims), vao::Region::whole(viewOf(vd, dims)), { 7, 2, 3 }, 1e6 + 5);
  expectEveryMethodMatchesCpu(
    viewOf(v32, dims), vao::Region::whole(viewOf(v32, dims)), { 3, 5, 2 }, 1000.0);
}

TEST(CudaAmbientOcclusion, SubRegionsAndStridedComponent)
{
  VAO_REQUIRE_CUDA_DEVICE();
  const vao::Index3 dims = { 41, 29, 17 };
  const auto v16 = randomVolume<std::int16_t>(dims, -1024, 1600, 221);
  const vao::Region regions[] = { { { 3, 2, 5 }, { 9, 7, 11 } }, { { 0, 0, 9 }, { 41, 29, 8 } },
    { { 40, 0, 16 }, { 1, 29, 1 } } };
  for (const auto& region : regions)
  {
    expectEveryMethodMatchesCpu(viewOf(v16, dims), region, { 5, 5, 5 }, 200.0);
    expectEveryMethodMatchesCpu(viewOf(v16, dims), region, { 12, 0, 5 }, 200.0);
  }
  // One float component of three, through voxelStride 3.
  const auto scalar = randomVolume<float>(dims, -1, 1, 222);
  std::vector<float> interleaved(scalar.size() * 3, 1e30f);
  for (std::size_t i = 0; i < scalar.size(); ++i)
  {
    interleaved[3 * i + 2] = scalar[i];
  }
  vao::VolumeView strided = viewOf(interleaved, dims, 3);
  strided.data = interleaved.data() + 2;
  expectEveryMethodMatchesCpu(strided, vao::Region::whole(strided), { 4, 4, 4 }, 0.1);
  expectEveryMethodMatchesCpu(strided, regions[0], { 7, 2, 3 }, 0.1);
}

// ---------------------------------------------------------------------------------------
// Arguments, timing and repeatability.

TEST(CudaValidation, RejectsBadArgumentsWithAMessage)
{
  VAO_REQUIRE_CUDA_DEVICE();
  const vao::Index3 dims = { 8, 7, 6 };
  const auto v = randomVolume<float>(dims, 0, 1, 301);
  const auto view = viewOf(v, dims);
  const auto whole = vao::Region::whole(view);
  std::vector<float> open(whole.voxelCount());
  StatsArrays stats(whole.voxelCount(), 0.0);

  vao::AmbientOcclusionParameters p;
  p.radius = { 2, -1, 2 };
  vao::Status status = vao::cuda::computeAmbientOcclusion(view, whole, p, { open.data(), nullptr });
  EXPECT_FALSE(status.ok) << "negative radius accepted";
  EXPECT_FALSE(status.message.empty());
  status = vao::cuda::computeBoxStatistics(view, whole, { -1, 0, 0 }, stats.output());
  EXPECT_FALSE(status.ok) << "negative radius accepted";
  EXPECT_FALSE(status.message.empty());

  for (auto method : { vao::Method::ExactBox, vao::Method::ExactSphere })
  {
    p.radius = { 1, -1, 1 };
    p.method = method;
    status = vao::cuda::computeAmbientOcclusion(view, whole, p, { open.data(), nullptr });
    EXPECT_FALSE(status.ok) << "exact method " << static_cast<int>(method)
                            << " accepted a negative radius";
    EXPECT_FALSE(status.deviceFailure) << "bad input is not a device failure";
  }

  p.method = vao::Method::GaussianCdf;
  p.queryMode = vao::QueryMode::IsoValue;
  p.isoValue = std::nan("");
  status = vao::cuda::computeAmbientOcclusion(view, whole, p, { open.data(), nullptr });
  EXPECT_FALSE(status.ok) << "NaN iso-value accepted (the CPU rejects it)";

  const vao::Region outside{ { 3, 0, 0 }, { 8, 7, 6 } };
  status = vao::cuda::computeBoxStatistics(view, outside, { 1, 1, 1 }, stats.output());
  EXPECT_FALSE(status.ok) << "region outside the volume accepted";
  EXPECT_FALSE(status.message.empty());
  vao::VolumeView null = view;
  null.data = nullptr;
  status = vao::cuda::computeBoxStatistics(null, whole, { 1, 1, 1 }, stats.output());
  EXPECT_FALSE(status.ok) << "null data accepted";
}

TEST(CudaTiming, FillsTimingAndRepeatsBitForBit)
{
  VAO_REQUIRE_CUDA_DEVICE();
  const vao::Index3 dims = { 64, 48, 33 };
  const auto v = randomVolume<std::int16_t>(dims, -1024, 1600, 401);
  const auto view = viewOf(v, dims);
  const auto whole = vao::Region::whole(view);
  vao::AmbientOcclusionParameters p;
  p.method = vao::Method::GaussianCdf;
  p.radius = { 5, 5, 5 };
  std::vector<float> first(whole.voxelCount()), second(whole.voxelCount());
  vao::cuda::Timing timing;
  vao::Status status =
    vao::cuda::computeAmbientOcclusion(view, whole, p, { first.data(), nullptr }, {}, &timing);
  ASSERT_TRUE(status.ok) << status.message;
  EXPECT_GT(timing.kernelMilliseconds, 0.0);
  EXPECT_GE(timing.totalMilliseconds, timing.kernelMilliseconds);
  ASSERT_FALSE(timing.passes.empty());
  for (const auto& pass : timing.passes)
  {
    EXPECT_FALSE(pass.name.empty());
    EXPECT_GE(pass.milliseconds, 0.0) << pass.name;
    EXPECT_GT(pass.bytes, 0.0) << pass.name;
  }
  // A second call with the same Timing starts afresh (no accumulation of passes).
  const std::size_t passCount = timing.passes.size();
  status =
    vao::cuda::computeAmbientOcclusion(view, whole, p, { second.data(), nullptr }, {}, &timing);
  ASSERT_TRUE(status.ok) << status.message;
  EXPECT_EQ(timing.passes.size(), passCount);
  EXPECT_EQ(first, second) << "two GPU runs differ";

  StatsArrays stats(whole.voxelCount(), 0.0);
  vao::cuda::Timing statsTiming;
  status = vao::cuda::computeBoxStatistics(view, whole, p.radius, stats.output(), {}, &statsTiming);
  ASSERT_TRUE(status.ok) << status.message;
  EXPECT_GT(statsTiming.kernelMilliseconds, 0.0);
  EXPECT_GE(statsTiming.totalMilliseconds, statsTiming.kernelMilliseconds);
  EXPECT_FALSE(statsTiming.passes.empty());
  EXPECT_GT(vao::cuda::measureCopyBandwidth(64.0 * 1024 * 1024), 0.0);
}

TEST(CudaTransfers, SlabsThroughPinnedStagingEqualTheCpuAndMoveEachByteOnce)
{
  VAO_REQUIRE_CUDA_DEVICE();
  // Tall enough for four z slabs (SlabPlan.h), so uploads, kernels and downloads overlap.
  const vao::Index3 tall = { 40, 30, 300 };
  const auto v16 = randomVolume<std::int16_t>(tall, -1024, 1600, 411);
  const auto view = viewOf(v16, tall);
  const vao::Region whole = vao::Region::whole(view), inner{ { 2, 3, 20 }, { 35, 25, 260 } };
  expectEveryMethodMatchesCpu(view, whole, { 3, 3, 3 }, 100.0);
  expectEveryMethodMatchesCpu(view, inner, { 6, 2, 9 }, 100.0);
  vao::AmbientOcclusionParameters p;
  p.method = vao::Method::GaussianCdf;
  p.radius = { 3, 3, 3 };
  std::vector<float> openness(whole.voxelCount()), variance(whole.voxelCount());
  vao::cuda::Timing timing;
  const vao::Status status = vao::cuda::computeAmbientOcclusion(
    view, whole, p, { openness.data(), variance.data() }, {}, &timing);
  ASSERT_TRUE(status.ok) << status.message;
  EXPECT_EQ(timing.uploadBytes, 2.0 * whole.voxelCount());   // each slice once, no halo twice
  EXPECT_EQ(timing.downloadBytes, 8.0 * whole.voxelCount()); // two float outputs
  EXPECT_GT(timing.uploadMilliseconds, 0.0);
  EXPECT_GT(timing.downloadMilliseconds, 0.0);
  // A smaller call after a larger one, and a larger one again, reuse the cached buffers.
  const vao::Index3 small = { 9, 7, 5 };
  const auto f32 = randomVolume<float>(small, -1, 1, 412);
  expectEveryMethodMatchesCpu(
    viewOf(f32, small), vao::Region::whole(viewOf(f32, small)), { 2, 2, 2 }, 0.1);
  // A failure after the first upload leaves nothing in flight for the next call.
  vao::cuda::injectDeviceFailures(1);
  std::vector<float> failed(whole.voxelCount());
  EXPECT_TRUE(
    vao::cuda::computeAmbientOcclusion(view, whole, p, { failed.data(), nullptr }).deviceFailure);
  expectEveryMethodMatchesCpu(view, whole, { 3, 3, 3 }, 100.0);
}

} // namespace

// ---------------------------------------------------------------------------------------
// The counting methods (Histogram CDF, Exact Box, Exact Sphere): the same counts on the
// device, so the same floats as the CPU; the variance from the moments, to 1e-5.

namespace
{

void expectCountsLikeTheCpu(const vao::VolumeView& view, const vao::Region& region,
  const vao::AmbientOcclusionParameters& p, const std::string& what)
{
  const size_t n = static_cast<size_t>(region.voxelCount());
  std::vector<float> cpu(n), gpu(n, -1.0f), cpuVar(n), gpuVar(n, -1.0f);
  ASSERT_TRUE(vao::computeAmbientOcclusion(view, region, p, { cpu.data(), cpuVar.data() }).ok);
  const vao::Status status =
    vao::cuda::computeAmbientOcclusion(view, region, p, { gpu.data(), gpuVar.data() });
  ASSERT_TRUE(status.ok) << status.message;
  for (size_t i = 0; i < n; ++i)
  {
    ASSERT_EQ(gpu[i], cpu[i]) << "voxel " << i << " " << what;
    ASSERT_NEAR(gpuVar[i], cpuVar[i], 1e-5 * std::max(1.0f, std::abs(cpuVar[i])));
  }
}

} // namespace

TEST(CudaAmbientOcclusion, ExactBoxAndSphereEqualTheCpu)
{
  VAO_REQUIRE_CUDA_DEVICE();
  const vao::Index3 dims = { 67, 45, 39 };
  const auto v16 = randomVolume<std::int16_t>(dims, -40, 40, 221);
  const auto vf = randomVolume<float>(dims, -1, 1, 222);
  auto check = [&](const vao::VolumeView& view, const vao::Region& region, vao::Radius radius,
                 vao::Method method, vao::QueryMode query, double iso)
  {
    vao::AmbientOcclusionParameters p;
    p.method = method;
    p.radius = radius;
    p.queryMode = query;
    p.isoValue = iso;
    expectCountsLikeTheCpu(view, region, p, "method " + std::to_string(static_cast<int>(method)));
  };
  const vao::Region inner{ { 5, 3, 7 }, { 50, 30, 20 } };
  for (auto method : { vao::Method::ExactBox, vao::Method::ExactSphere })
  {
    check(viewOf(v16, dims), vao::Region::whole(viewOf(v16, dims)), { 5, 5, 5 }, method,
      vao::QueryMode::VoxelValue, 0.0);
    check(viewOf(vf, dims), inner, { 3, 7, 0 }, method, vao::QueryMode::IsoValue, 0.2);
    check(viewOf(v16, dims), inner, { 12, 12, 12 }, method, vao::QueryMode::VoxelValue, 0.0);
  }
}

TEST(CudaAmbientOcclusion, HistogramCdfEqualsTheCpu)
{
  VAO_REQUIRE_CUDA_DEVICE();
  const vao::Index3 dims = { 67, 45, 39 };
  const auto v16 = randomVolume<std::int16_t>(dims, -1024, 2000, 211);
  const auto v8 = randomVolume<std::uint8_t>(dims, 0, 256, 212);
  const auto vf = randomVolume<float>(dims, -1, 1, 213);
  auto check = [&](const vao::VolumeView& view, const vao::Region& region, vao::Radius radius,
                 int bins, vao::QueryMode query, double iso)
  {
    vao::AmbientOcclusionParameters p;
    p.method = vao::Method::HistogramCdf;
    p.radius = radius;
    p.queryMode = query;
    p.isoValue = iso;
    ASSERT_TRUE(vao::volumeThresholds(view, bins, p.thresholds).ok);
    expectCountsLikeTheCpu(view, region, p, "bins " + std::to_string(bins));
  };
  const vao::Region inner{ { 5, 3, 7 }, { 50, 30, 20 } };
  for (int bins : { 2, 9, 64, 256 })
  {
    check(viewOf(v16, dims), vao::Region::whole(viewOf(v16, dims)), { 5, 5, 5 }, bins,
      vao::QueryMode::VoxelValue, 0.0);
    check(viewOf(v8, dims), inner, { 3, 7, 2 }, bins, vao::QueryMode::VoxelValue, 0.0);
    check(viewOf(vf, dims), inner, { 10, 10, 10 }, bins, vao::QueryMode::IsoValue, 0.2);
  }
  // 41^3 voxels: more than 16-bit counts hold on the CPU; the device counts in int.
  check(viewOf(v8, dims), vao::Region::whole(viewOf(v8, dims)), { 20, 20, 19 }, 64,
    vao::QueryMode::VoxelValue, 0.0);
}
