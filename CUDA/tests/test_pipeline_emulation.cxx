// The GPU pipeline (src/cuda/common/Pipeline.h) run on the host: every kernel's per-thread
// code in a loop, the transposes as plain loops. It checks the indexing, layouts, segments and van
// Herk blocks of the CUDA backend against the CPU library on machines without a GPU; test_cuda.cxx
// checks the real device where there is one.
#include "PipelineEmulation.h"

#include "cpu/exact_reference/ExactReference.h"
#include "cpu/moment_pyramid/PyramidPlan.h"
#include "cuda/common/Pipeline.h"
#include "cuda/exact_reference/ExactPipeline.h"
#include "cuda/histogram_cdf/HistogramPipeline.h"
#include "cuda/moment_pyramid/PyramidPipeline.h"

#include "vao/HistogramCdf.h"
#include "vao/VarianceOcclusionMap.h"

#include <gtest/gtest.h>

#include <limits>
#include <string>

using namespace vaotest;
using vao::gpu::Index;

namespace
{

// Each test runs the separate passes and the fused pass (FusedStatistics.h; its own
// checks are in test_fused_emulation.cxx); the volumes span two tiles of it across x and
// y, the last ones partly outside the region.
const Emulation kBothPipelines[] = { Emulation{}, Emulation{ true, 0, false } };

TEST(GpuPipelineOnHost, StatisticsEqualTheCpuForEveryRadiusAndType)
{
  const vao::Index3 dims = { 37, 13, 11 };
  const auto u8 = randomVolume<std::uint8_t>(dims, 0, 255, 1);
  const auto i16 = randomVolume<std::int16_t>(dims, -1024, 3000, 2);
  const auto f32 = randomVolume<float>(dims, -1, 1, 3);
  const auto f64 = randomVolume<double>(dims, 1e6, 1e6 + 5, 4);
  const auto whole = vao::Region::whole(viewOf(u8, dims));
  for (const Emulation& how : kBothPipelines)
  {
    SCOPED_TRACE(how.fused ? "fused" : "separate passes");
    for (int r = 0; r <= 12; ++r)
    {
      SCOPED_TRACE(r);
      expectStatisticsLikeTheCpu(u8, dims, whole, { r, r, r }, how);
      expectStatisticsLikeTheCpu(i16, dims, whole, { r, r, r }, how);
      expectStatisticsLikeTheCpu(f32, dims, whole, { r, r, r }, how);
    }
    expectStatisticsLikeTheCpu(f64, dims, whole, { 2, 3, 1 }, how);
    for (const vao::Radius& r : { vao::Radius{ 1, 4, 0 }, vao::Radius{ 7, 2, 3 },
           vao::Radius{ 12, 0, 5 }, vao::Radius{ 30, 1, 40 } })
      expectStatisticsLikeTheCpu(i16, dims, whole, r, how);
  }
}

TEST(GpuPipelineOnHost, SubRegionsEqualTheCpu)
{
  const vao::Index3 dims = { 41, 17, 21 };
  const auto i16 = randomVolume<std::int16_t>(dims, -500, 500, 5);
  for (const vao::Region& region :
    { vao::Region{ { 3, 2, 5 }, { 35, 7, 11 } }, vao::Region{ { 0, 16, 0 }, { 41, 1, 21 } },
      vao::Region{ { 40, 0, 20 }, { 1, 17, 1 } }, vao::Region{ { 33, 8, 0 }, { 8, 9, 21 } } })
    for (const Emulation& how : kBothPipelines)
    {
      expectStatisticsLikeTheCpu(i16, dims, region, { 4, 2, 3 }, how);
      expectOpennessLikeTheCpu(i16, dims, region, { 4, 2, 3 }, vao::Method::CdfReconstruction,
        vao::QueryMode::VoxelValue, 0, how);
      expectOpennessLikeTheCpu(i16, dims, region, { 4, 2, 3 }, vao::Method::GaussianCdf,
        vao::QueryMode::IsoValue, 40, how);
    }
  const vao::Index3 thin = { 1, 70, 2 };
  const auto u8 = randomVolume<std::uint8_t>(thin, 0, 255, 16);
  for (const Emulation& how : kBothPipelines)
    expectStatisticsLikeTheCpu(u8, thin, vao::Region{ { 0, 0, 0 }, thin }, { 3, 3, 3 }, how);
}

TEST(GpuPipelineOnHost, EveryEstimatorEqualsTheCpu)
{
  const vao::Index3 dims = { 35, 11, 9 };
  const auto i16 = randomVolume<std::int16_t>(dims, -1024, 1600, 6);
  const auto f32 = randomVolume<float>(dims, -1, 1, 7);
  const auto whole = vao::Region::whole(viewOf(i16, dims));
  for (const Emulation& how : kBothPipelines)
    for (auto method :
      { vao::Method::CdfReconstruction, vao::Method::GaussianCdf, vao::Method::Chebyshev })
      for (int r : { 0, 1, 3, 6, 12 })
      {
        expectOpennessLikeTheCpu(
          i16, dims, whole, { r, r, r }, method, vao::QueryMode::VoxelValue, 0, how);
        expectOpennessLikeTheCpu(
          f32, dims, whole, { r, r, r }, method, vao::QueryMode::IsoValue, 0.2, how);
      }
}

} // namespace

namespace
{

/// The parameters of a query of `method` with `radius`, of the voxel's value or of isoValue.
vao::AmbientOcclusionParameters queryOf(
  vao::Method method, const vao::Radius& radius, bool iso, double isoValue)
{
  vao::AmbientOcclusionParameters p;
  p.method = method;
  p.radius = radius;
  p.queryMode = iso ? vao::QueryMode::IsoValue : vao::QueryMode::VoxelValue;
  p.isoValue = isoValue;
  return p;
}

/// The device's passes run on the host, passes(executor, block, geometry, out), equal the
/// CPU library's result of `p` voxel for voxel.
template <class T, class Passes>
void expectPassesLikeTheCpu(const std::vector<T>& v, const vao::Index3& dims,
  const vao::Region& region, const vao::AmbientOcclusionParameters& p, Passes&& passes)
{
  std::vector<float> cpu(region.voxelCount());
  ASSERT_TRUE(vao::computeAmbientOcclusion(viewOf(v, dims), region, p, { cpu.data(), nullptr }).ok);
  const auto g = vao::gpu::geometryFor(dims, region, p.radius);
  const std::vector<T> block = blockOf(v, dims, region, g);
  std::vector<float> gpu(region.voxelCount(), -1.0f);
  HostExecutor ex;
  passes(ex, block.data(), g, gpu.data());
  for (size_t i = 0; i < cpu.size(); ++i)
    ASSERT_EQ(gpu[i], cpu[i]) << "voxel " << i << " method " << static_cast<int>(p.method);
}

/// Histogram CDF through the GPU pipeline on the host against the CPU library.
template <class T>
void expectHistogramLikeTheCpu(const std::vector<T>& v, const vao::Index3& dims,
  const vao::Region& region, const vao::Radius& radius, int bins, bool iso, double isoValue)
{
  vao::AmbientOcclusionParameters p = queryOf(vao::Method::HistogramCdf, radius, iso, isoValue);
  ASSERT_TRUE(vao::volumeThresholds(viewOf(v, dims), bins, p.thresholds).ok);
  SCOPED_TRACE("bins " + std::to_string(bins));
  expectPassesLikeTheCpu(v, dims, region, p,
    [&](HostExecutor& ex, const T* block, const auto& g, float* out)
    {
      vao::gpu::runHistogramPasses<T>(ex, block, g, p.thresholds.data(),
        static_cast<int>(p.thresholds.size()), iso, isoValue, out);
    });
}

/// Exact Box or Exact Sphere through the device's passes equals the CPU reference voxel
/// for voxel; `visitsPerLaunch` small splits the region into slabs of one or a few slices.
template <class T>
void expectExactLikeTheCpu(const std::vector<T>& v, const vao::Index3& dims,
  const vao::Region& region, const vao::Radius& radius, vao::Method method, bool iso,
  double isoValue, double visitsPerLaunch)
{
  expectPassesLikeTheCpu(v, dims, region, queryOf(method, radius, iso, isoValue),
    [&](HostExecutor& ex, const T* block, const auto& g, float* out)
    {
      vao::gpu::runExactPasses<T>(ex, block, g,
        vao::detail::neighbourhoodRowHalfWidths(radius, method == vao::Method::ExactSphere), iso,
        isoValue, out, 0.0, 1.0, visitsPerLaunch);
    });
}

/// The device's pyramid passes on the host against the CPU's buildMomentPyramid: the same
/// levels, dims and geometry, the moments equal but for the rounding of the CPU's fused
/// multiply-adds (1e-5 is the device's bar; they agree far closer).
template <class T>
void expectPyramidLikeTheCpu(
  const std::vector<T>& v, const vao::Index3& dims, const vao::PyramidParameters& parameters)
{
  const std::array<double, 3> origin = { -3.0, 2.5, 7.0 }, spacing = { 0.8, 1.1, 2.0 };
  std::vector<vao::MomentLevel> cpu;
  ASSERT_TRUE(vao::buildMomentPyramid(viewOf(v, dims), origin, spacing, parameters, cpu).ok);
  vao::detail::PyramidSetup setup;
  ASSERT_TRUE(vao::detail::preparePyramid(viewOf(v, dims), origin, spacing, parameters, setup).ok);
  std::vector<vao::MomentLevel> gpu;
  HostExecutor ex;
  vao::gpu::runPyramid<T>(ex, v.data(), dims, setup, parameters.levels, gpu);
  vao::detail::setLevelGeometry(gpu, origin, spacing, setup);
  ASSERT_EQ(gpu.size(), cpu.size());
  for (size_t l = 0; l < cpu.size(); ++l)
  {
    ASSERT_EQ(gpu[l].dims, cpu[l].dims) << "level " << l;
    EXPECT_EQ(gpu[l].spacing, cpu[l].spacing);
    EXPECT_EQ(gpu[l].kernelRadius, cpu[l].kernelRadius);
    EXPECT_EQ(gpu[l].roundingVariance, cpu[l].roundingVariance);
    double meanScale = 1.0, varianceScale = 0.0;
    for (size_t i = 0; i < cpu[l].mean.size(); ++i)
    {
      meanScale = std::max(meanScale, std::abs(static_cast<double>(cpu[l].mean[i])));
      varianceScale = std::max(varianceScale, static_cast<double>(cpu[l].variance[i]));
    }
    ASSERT_GT(varianceScale, 0.0);
    for (size_t i = 0; i < cpu[l].mean.size(); ++i)
    {
      ASSERT_NEAR(gpu[l].mean[i], cpu[l].mean[i], 1e-6 * meanScale)
        << "level " << l << " voxel " << i;
      ASSERT_NEAR(
        gpu[l].variance[i], cpu[l].variance[i], 1e-6 * varianceScale + cpu[l].roundingVariance)
        << "level " << l << " voxel " << i;
    }
  }
}

} // namespace

TEST(GpuPipelineOnHost, MomentPyramidEqualsTheCpu)
{
  const vao::Index3 odd = { 19, 14, 11 }, thin = { 2, 9, 6 };
  const auto i16 = randomVolume<std::int16_t>(odd, -1024, 2000, 321);
  const auto u8 = randomVolume<std::uint8_t>(thin, 0, 256, 322);
  const auto f32 = randomVolume<float>(odd, 1000, 1001, 323); // large mean, small spread
  expectPyramidLikeTheCpu(i16, odd, { 4, false });
  expectPyramidLikeTheCpu(i16, odd, { 3, true });
  expectPyramidLikeTheCpu(u8, thin, { 2, false });
  expectPyramidLikeTheCpu(f32, odd, { 5, false });
}

TEST(GpuPipelineOnHost, ExactBoxAndSphereEqualTheCpu)
{
  const vao::Index3 dims = { 17, 12, 10 };
  const auto i16 = randomVolume<std::int16_t>(dims, -20, 20, 311); // many ties with the query
  const auto u8 = randomVolume<std::uint8_t>(dims, 0, 256, 312);
  const auto f32 = randomVolume<float>(dims, -1, 1, 313);
  const vao::Region whole{ { 0, 0, 0 }, dims }, inner{ { 3, 2, 4 }, { 11, 8, 5 } };
  for (vao::Method method : { vao::Method::ExactBox, vao::Method::ExactSphere })
  {
    expectExactLikeTheCpu(i16, dims, whole, { 2, 2, 2 }, method, false, 0.0, 1 << 30);
    expectExactLikeTheCpu(i16, dims, inner, { 3, 1, 4 }, method, true, 0.0, 500.0);
    expectExactLikeTheCpu(u8, dims, inner, { 0, 3, 2 }, method, false, 0.0, 1.0);
    expectExactLikeTheCpu(f32, dims, whole, { 4, 0, 0 }, method, true, 0.1, 2000.0);
    expectExactLikeTheCpu(f32, dims, inner, { 20, 20, 20 }, method, false, 0.0, 1 << 30);
  }
}

TEST(GpuPipelineOnHost, HistogramCdfEqualsTheCpu)
{
  const vao::Index3 dims = { 19, 13, 11 };
  const auto i16 = randomVolume<std::int16_t>(dims, -1024, 2000, 301);
  const auto u8 = randomVolume<std::uint8_t>(dims, 0, 256, 302);
  const auto f32 = randomVolume<float>(dims, -1, 1, 303);
  const vao::Region whole{ { 0, 0, 0 }, dims }, inner{ { 3, 2, 4 }, { 11, 8, 5 } };
  for (int bins : { 2, 7, 64 })
  {
    expectHistogramLikeTheCpu(i16, dims, whole, { 2, 2, 2 }, bins, false, 0.0);
    expectHistogramLikeTheCpu(u8, dims, inner, { 3, 1, 4 }, bins, false, 0.0);
    expectHistogramLikeTheCpu(f32, dims, inner, { 1, 5, 2 }, bins, true, 0.1);
    expectHistogramLikeTheCpu(i16, dims, whole, { 20, 20, 20 }, bins, false, 0.0);
  }
  expectHistogramLikeTheCpu(u8, dims, whole, { 2, 3, 2 }, 256, false, 0.0);
  // A tile and halo beyond a block's shared memory: the separate passes.
  const auto g = vao::gpu::geometryFor(dims, whole, { 70, 70, 2 });
  ASSERT_FALSE(
    (vao::gpu::fusedPassFits<int, vao::gpu::Bin>(g, false, HostExecutor().sharedLimit())));
  expectHistogramLikeTheCpu(i16, dims, whole, { 70, 70, 2 }, 7, false, 0.0);
  expectHistogramLikeTheCpu(f32, dims, inner, { 70, 70, 2 }, 64, true, 0.1);
}
