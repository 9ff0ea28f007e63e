// Helpers of the CUDA backend tests: the comparison of GPU results with the CPU's (the
// reference) and the skip where there is no device.
#pragma once

#include "ResultComparison.h"
#include "TestVolumes.h"

#include "vao/Cuda.h"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>
#include <sstream>
#include <string>

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

namespace vaotest
{

constexpr double kStatsTolerance = 1e-5;    // relative, for mean and variance
constexpr double kOpennessTolerance = 1e-5; // absolute

inline std::string describe(const vao::Radius& r)
{
  std::ostringstream s;
  s << "radius (" << r.x << "," << r.y << "," << r.z << ")";
  return s.str();
}

inline std::string describe(const vao::VolumeView& view, const vao::Region& region)
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
inline int& detailsLeft()
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

inline bool mayReportDetail()
{
  return detailsLeft()-- > 0;
}

/// Index of region voxel k in the volume, as (x, y, z).
inline vao::Index3 voxelOf(const vao::Region& region, std::int64_t k)
{
  const std::int64_t x = k % region.size[0];
  const std::int64_t y = (k / region.size[0]) % region.size[1];
  const std::int64_t z = k / (region.size[0] * region.size[1]);
  return { region.begin[0] + x, region.begin[1] + y, region.begin[2] + z };
}

/// GPU box statistics of the region against the CPU's: count, minimum and maximum
/// exactly, mean and variance to kStatsTolerance (relative).
inline void expectStatsMatchCpu(
  const vao::VolumeView& view, const vao::Region& region, const vao::Radius& r)
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
      gpu.maximum[k] == cpu.maximum[k] &&
      closeRelative(gpu.mean[k], cpu.mean[k], kStatsTolerance) &&
      closeRelative(gpu.variance[k], cpu.variance[k], kStatsTolerance);
    if (!ok && failures++ < 5 && mayReportDetail())
    {
      const vao::Index3 p = voxelOf(region, k);
      ADD_FAILURE() << "voxel (" << p[0] << "," << p[1] << "," << p[2] << "), GPU vs CPU: count "
                    << gpu.count[k] << " vs " << cpu.count[k] << ", mean " << gpu.mean[k] << " vs "
                    << cpu.mean[k] << ", variance " << gpu.variance[k] << " vs " << cpu.variance[k]
                    << ", min " << gpu.minimum[k] << " vs " << cpu.minimum[k] << ", max "
                    << gpu.maximum[k] << " vs " << cpu.maximum[k];
    }
  }
  EXPECT_EQ(failures, 0) << "voxels that differ, of " << n;
}

/// GPU openness and variance of the region against the CPU's: openness to
/// kOpennessTolerance (absolute), variance to kStatsTolerance (relative).
inline void expectOpennessMatchesCpu(const vao::VolumeView& view, const vao::Region& region,
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
                    << (withVariance ? gpuVar[k] : 0.0f) << " vs "
                    << (withVariance ? cpuVar[k] : 0.0f);
    }
  }
  EXPECT_EQ(failures, 0) << "voxels that differ, of " << n;
}

/// Every separable method, with the voxel's value and with an iso-value as the query.
inline void expectEveryMethodMatchesCpu(
  const vao::VolumeView& view, const vao::Region& region, const vao::Radius& r, double isoValue)
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

} // namespace vaotest
