// The CUDA backend against the CPU functions (the reference): the same statistics and the
// same openness on random odd-sized volumes, every radius 0..12, anisotropic radii, radii
// larger than the volume, several scalar types, sub-regions and a strided component.
//
// Every test that needs a device first asks vao::cuda::deviceStatus() and skips, with the
// reason, where there is none; CudaBackend.ReportsItsStateWithoutCrashing runs everywhere.
#include "TestVolumes.h"

#include "vao/Cuda.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <sstream>
#include <string>

using namespace vaotest;

// A macro, not a function: GTEST_SKIP() returns from the test body that expands it.
#define VAO_REQUIRE_CUDA_DEVICE()                                                                  \
  do                                                                                               \
  {                                                                                                \
    const vao::cuda::DeviceStatus vaoDevice = vao::cuda::deviceStatus();                           \
    if (!vaoDevice.available)                                                                      \
    {                                                                                              \
      GTEST_SKIP() << "no CUDA device: " << vaoDevice.description;                                 \
    }                                                                                              \
  } while (false)

namespace
{

constexpr double kStatsTolerance = 1e-5;    // relative, for mean and variance
constexpr double kOpennessTolerance = 1e-5; // absolute

bool closeRelative(double a, double b, double tolerance)
{
  return std::abs(a - b) <= tolerance * std::max(1.0, std::abs(b));
}

std::string describe(const vao::Radius& r)
{
  std::ostringstream s;
  s << "radius (" << r.x << "," << r.y << "," << r.z << ")";
  return s.str();
}

std::string describe(const vao::VolumeView& view, const vao::Region& region)
{
  std::ostringstream s;
  s << vao::scalarTypeName(view.type) << " " << view.dims[0] << "x" << view.dims[1] << "x"
    << view.dims[2] << " stride " << view.voxelStride << ", region [" << region.begin[0] << ","
    << region.begin[1] << "," << region.begin[2] << "] + " << region.size[0] << "x"
    << region.size[1] << "x" << region.size[2];
  return s.str();
}

/// Voxel-level failure messages left in the current test: a systematic bug would print
/// thousands, so after 20 the remaining comparisons of that test are skipped (it has
/// failed already).
int& detailsLeft()
{
  static const ::testing::TestInfo* test = nullptr;
  static int left = 0;
  const ::testing::TestInfo* current = ::testing::UnitTest::GetInstance()->current_test_info();
  if (current != test)
  {
    test = current;
    left = 20;
  }
  return left;
}

bool mayReportDetail()
{
  return detailsLeft()-- > 0;
}

/// Index of region voxel k in the volume, as (x, y, z).
vao::Index3 voxelOf(const vao::Region& region, std::int64_t k)
{
  const std::int64_t x = k % region.size[0];
  const std::int64_t y = (k / region.size[0]) % region.size[1];
  const std::int64_t z = k / (region.size[0] * region.size[1]);
  return { region.begin[0] + x, region.begin[1] + y, region.begin[2] + z };
}

struct StatsArrays
{
  std::vector<double> count, mean, variance, minimum, maximum;
  explicit StatsArrays(std::int64_t n, double fill)
    : count(n, fill), mean(n, fill), variance(n, fill), minimum(n, fill), maximum(n, fill)
  {
  }
  vao::BoxStatisticsOutput output()
  {
    return { count.data(), mean.data(), variance.data(), minimum.data(), maximum.data() };
  }
};

/// GPU box statistics of the region against the CPU's: count, minimum and maximum
/// exactly, mean and variance to kStatsTolerance (relative).
void expectStatsMatchCpu(const vao::VolumeView& view, const vao::Region& region, const vao::Radius& r)
{
  if (detailsLeft() <= 0)
  {
    return;
  }
  SCOPED_TRACE(describe(view, region) + ", " + describe(r));
  const std::int64_t n = region.voxelCount();
  StatsArrays cpu(n, -7.0), gpu(n, -9.0);
  const vao::Status cpuStatus = vao::computeBoxStatistics(view, region, r, cpu.output());
  ASSERT_TRUE(cpuStatus.ok) << cpuStatus.message;
  const vao::Status gpuStatus = vao::cuda::computeBoxStatistics(view, region, r, gpu.output());
  ASSERT_TRUE(gpuStatus.ok) << gpuStatus.message;
  std::int64_t failures = 0;
  for (std::int64_t k = 0; k < n; ++k)
  {
    const bool ok = gpu.count[k] == cpu.count[k] && gpu.minimum[k] == cpu.minimum[k] &&
      gpu.maximum[k] == cpu.maximum[k] && closeRelative(gpu.mean[k], cpu.mean[k], kStatsTolerance) &&
      closeRelative(gpu.variance[k], cpu.variance[k], kStatsTolerance);
    if (!ok && failures++ < 5 && mayReportDetail())
    {
      const vao::Index3 p = voxelOf(region, k);
      ADD_FAILURE() << "voxel (" << p[0] << "," << p[1] << "," << p[2] << "), GPU vs CPU: count "
                    << gpu.count[k] << " vs " << cpu.count[k] << ", mean " << gpu.mean[k]
                    << " vs " << cpu.mean[k] << ", variance " << gpu.variance[k] << " vs "
                    << cpu.variance[k] << ", min " << gpu.minimum[k] << " vs " << cpu.minimum[k]
                    << ", max " << gpu.maximum[k] << " vs " << cpu.maximum[k];
    }
  }
  EXPECT_EQ(failures, 0) << "voxels that differ, of " << n;
}

struct MethodCase
{
  vao::Method method;
  vao::ErfMode erf;
  const char* name;
};

const MethodCase kSeparableMethods[] = {
  { vao::Method::CdfReconstruction, vao::ErfMode::Exact, "CdfReconstruction" },
  { vao::Method::GaussianCdf, vao::ErfMode::Exact, "GaussianCdf exact erf" },
  { vao::Method::GaussianCdf, vao::ErfMode::Winitzki, "GaussianCdf Winitzki erf" },
  { vao::Method::Chebyshev, vao::ErfMode::Exact, "Chebyshev" },
};

/// GPU openness and variance of the region against the CPU's: openness to
/// kOpennessTolerance (absolute), variance to kStatsTolerance (relative).
void expectOpennessMatchesCpu(const vao::VolumeView& view, const vao::Region& region,
  const vao::AmbientOcclusionParameters& p, bool withVariance)
{
  std::ostringstream what;
  what << describe(view, region) << ", " << describe(p.radius) << ", method "
       << static_cast<int>(p.method) << " erf " << static_cast<int>(p.erfMode) << ", query "
       << (p.queryMode == vao::QueryMode::IsoValue ? "iso " : "voxel ") << p.isoValue;
  if (detailsLeft() <= 0)
  {
    return;
  }
  SCOPED_TRACE(what.str());
  const std::int64_t n = region.voxelCount();
  std::vector<float> cpuOpen(n, -7.0f), gpuOpen(n, -9.0f), cpuVar(n, -7.0f), gpuVar(n, -9.0f);
  const vao::Status cpuStatus = vao::computeAmbientOcclusion(
    view, region, p, { cpuOpen.data(), withVariance ? cpuVar.data() : nullptr });
  ASSERT_TRUE(cpuStatus.ok) << cpuStatus.message;
  const vao::Status gpuStatus = vao::cuda::computeAmbientOcclusion(
    view, region, p, { gpuOpen.data(), withVariance ? gpuVar.data() : nullptr });
  ASSERT_TRUE(gpuStatus.ok) << gpuStatus.message;
  std::int64_t failures = 0;
  for (std::int64_t k = 0; k < n; ++k)
  {
    const bool opennessOk = std::abs(double(gpuOpen[k]) - double(cpuOpen[k])) <= kOpennessTolerance;
    const bool varianceOk = !withVariance || closeRelative(gpuVar[k], cpuVar[k], kStatsTolerance);
    if ((!opennessOk || !varianceOk) && failures++ < 5 && mayReportDetail())
    {
      const vao::Index3 v = voxelOf(region, k);
      ADD_FAILURE() << "voxel (" << v[0] << "," << v[1] << "," << v[2] << "), GPU vs CPU: openness "
                    << gpuOpen[k] << " vs " << cpuOpen[k] << ", variance "
                    << (withVariance ? gpuVar[k] : 0.0f) << " vs " << (withVariance ? cpuVar[k] : 0.0f);
    }
  }
  EXPECT_EQ(failures, 0) << "voxels that differ, of " << n;
}

/// Every separable method, with the voxel's value and with an iso-value as the query.
void expectEveryMethodMatchesCpu(const vao::VolumeView& view, const vao::Region& region,
  const vao::Radius& r, double isoValue)
{
  for (const MethodCase& m : kSeparableMethods)
  {
    SCOPED_TRACE(m.name);
    for (auto query : { vao::QueryMode::VoxelValue, vao::QueryMode::IsoValue })
    {
      vao::AmbientOcclusionParameters p;
      p.method = m.method;
      p.erfMode = m.erf;
      p.radius = r;
      p.queryMode = query;
      p.isoValue = isoValue;
      // The variance output on one method is enough: it does not depend on the method.
      expectOpennessMatchesCpu(view, region, p, m.method == vao::Method::GaussianCdf);
    }
  }
}

// ---------------------------------------------------------------------------------------
// Runs on every machine: no device, no CUDA build, or a device.

TEST(CudaBackend, ReportsItsStateWithoutCrashing)
{
  const vao::cuda::DeviceStatus device = vao::cuda::deviceStatus();
  EXPECT_FALSE(device.description.empty()) << "deviceStatus() should name the device or say why there is none";
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
    EXPECT_EQ(vao::cuda::measureCopyBandwidth(1 << 24), 0.0);
    std::cout << "[          ] built() = " << vao::cuda::built() << ", no device: " << device.description
              << "\n[          ] computeBoxStatistics says: " << statsStatus.message << std::endl;
  }
}

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
  vao::BoxStatisticsOutput meanMax{ nullptr, gpu.mean.data(), nullptr, nullptr, gpu.maximum.data() };
  vao::Status status = vao::cuda::computeBoxStatistics(view, whole, r, meanMax);
  ASSERT_TRUE(status.ok) << status.message;
  vao::BoxStatisticsOutput varMin{ nullptr, nullptr, gpu.variance.data(), gpu.minimum.data(), nullptr };
  status = vao::cuda::computeBoxStatistics(view, whole, r, varMin);
  ASSERT_TRUE(status.ok) << status.message;
  std::int64_t failures = 0;
  for (std::int64_t k = 0; k < whole.voxelCount(); ++k)
  {
    const bool ok = gpu.count[k] == -9.0 && gpu.minimum[k] == cpu.minimum[k] &&
      gpu.maximum[k] == cpu.maximum[k] && closeRelative(gpu.mean[k], cpu.mean[k], kStatsTolerance) &&
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
    expectEveryMethodMatchesCpu(viewOf(v8, dims), vao::Region::whole(viewOf(v8, dims)), radius, 3.0);
    expectEveryMethodMatchesCpu(viewOf(v16, dims), vao::Region::whole(viewOf(v16, dims)), radius, 100.0);
    expectEveryMethodMatchesCpu(viewOf(vf, dims), vao::Region::whole(viewOf(vf, dims)), radius, 0.25);
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
  for (const vao::Radius& r : { vao::Radius{ 1, 4, 0 }, vao::Radius{ 7, 2, 3 }, vao::Radius{ 12, 0, 5 },
         vao::Radius{ 50, 50, 50 } })
  {
    expectEveryMethodMatchesCpu(viewOf(v16, dims), vao::Region::whole(viewOf(v16, dims)), r, 0.0);
    expectEveryMethodMatchesCpu(viewOf(vf, dims), vao::Region::whole(viewOf(vf, dims)), r, -0.5);
  }
  expectEveryMethodMatchesCpu(viewOf(vd, dims), vao::Region::whole(viewOf(vd, dims)), { 7, 2, 3 }, 1e6 + 5);
  expectEveryMethodMatchesCpu(viewOf(v32, dims), vao::Region::whole(viewOf(v32, dims)), { 3, 5, 2 }, 1000.0);
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
    p.radius = { 1, 1, 1 };
    p.method = method;
    status = vao::cuda::computeAmbientOcclusion(view, whole, p, { open.data(), nullptr });
    EXPECT_FALSE(status.ok) << "exact method " << static_cast<int>(method) << " accepted on the GPU";
    EXPECT_FALSE(status.message.empty()) << "the refusal of an exact method must say why";
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
  vao::Status status = vao::cuda::computeAmbientOcclusion(view, whole, p, { first.data(), nullptr }, {}, &timing);
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
  status = vao::cuda::computeAmbientOcclusion(view, whole, p, { second.data(), nullptr }, {}, &timing);
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

} // namespace
