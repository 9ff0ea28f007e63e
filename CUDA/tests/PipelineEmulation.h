// The GPU pipeline's host emulation, shared by the emulation tests: an executor that runs
// each kernel as a loop over its threads, the block a region uploads, and Pipeline.h's
// passes set up as CudaBackend.cu sets them up.
#pragma once

#include "TestVolumes.h"

#include "VolumeAccess.h"
#include "cuda/common/FusedStatistics.h"
#include "cuda/common/Pipeline.h"
#include "cuda/common/SlabPlan.h"

#include "vao/AmbientOcclusion.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <vector>

namespace vaotest
{

using vao::gpu::Index;

/// FusedStatistics.h's Block on the host: a phase's items in a loop (backwards on demand:
/// an item that read what another item of its phase writes would then see other data).
struct HostBlock
{
  bool backwards;
  template <class F>
  void each(Index count, F&& f) const
  {
    for (Index k = 0; k < count; ++k)
      f(backwards ? count - 1 - k : k);
  }
};

/// A FusedStatistics.h kernel's blocks in a loop, each with fresh shared memory filled
/// with a poison value; phases forwards or backwards.
template <class Kernel>
void runBlocksOnHost(const Kernel& kernel, bool backwards)
{
  using Acc = typename Kernel::Acc;
  std::vector<Acc> shared(
    static_cast<size_t>((kernel.sharedBytes() + sizeof(Acc) - 1) / sizeof(Acc)));
  for (Index b = 0; b < kernel.blocks(); ++b)
  {
    std::fill(shared.begin(), shared.end(), std::numeric_limits<Acc>::max() / 3);
    kernel.run(HostBlock{ backwards }, b, shared.data());
  }
}

/// Runs kernels as loops over their thread indices. Fresh buffers are filled with a
/// poison value, so a pass that reads what no pass wrote shows up in the results.
class HostExecutor
{
public:
  template <class U>
  struct Buffer
  {
    std::vector<U> data;
    U* get() const { return data.empty() ? nullptr : const_cast<U*>(data.data()); }
  };

  template <class U>
  Buffer<U> allocate(Index count)
  {
    Buffer<U> buffer;
    buffer.data.assign(
      static_cast<size_t>(count), static_cast<U>(std::numeric_limits<U>::max() / 3));
    return buffer;
  }

  template <class U>
  Buffer<U> upload(const U* host, Index count)
  {
    Buffer<U> buffer;
    buffer.data.assign(host, host + count);
    return buffer;
  }

  template <class U>
  void download(U* host, const U* buffer, Index count)
  {
    std::copy(buffer, buffer + count, host);
  }

  template <class Kernel>
  void launch(const Kernel& kernel, const char*, double)
  {
    for (Index thread = 0; thread < kernel.threads(); ++thread)
    {
      kernel(thread);
    }
  }

  template <class U>
  void transpose(const U* in, U* out, Index nx, Index ny, Index nz, const char*)
  {
    for (Index z = 0; z < nz; ++z)
      for (Index y = 0; y < ny; ++y)
        for (Index x = 0; x < nx; ++x)
          out[(z * nx + x) * ny + y] = in[(z * ny + y) * nx + x];
  }

  template <class Kernel>
  void launchBlocks(const Kernel& kernel, const char*, double)
  {
    runBlocksOnHost(kernel, false);
  }

  /// An H100's: larger radii take the separate passes, as there.
  Index sharedLimit() const { return 227 * 1024; }

  void synchronize() {}
  void progress(double) {}
};

struct Results
{
  std::vector<float> openness, variance;
  std::vector<double> count, mean, varianceD, minimum, maximum;
};

/// The block the region reads, as CudaBackend.cu uploads it.
template <class T>
std::vector<T> blockOf(const std::vector<T>& v, const vao::Index3& dims, const vao::Region& region,
  const vao::gpu::RegionGeometry& g)
{
  std::vector<T> block;
  const Index x0 = region.begin[0] - g.ox, y0 = region.begin[1] - g.oy, z0 = region.begin[2] - g.oz;
  for (Index z = z0; z < z0 + g.sz; ++z)
    for (Index y = y0; y < y0 + g.sy; ++y)
      for (Index x = x0; x < x0 + g.sx; ++x)
        block.push_back(v[(z * dims[1] + y) * dims[0] + x]);
  return block;
}

/// How the host runs the device's passes: Pipeline.h's separate passes, or the fused pass
/// (FusedStatistics.h) over z slabs of `slabSlices` (0: SlabPlan.h's default) with each
/// block's phases run forwards or backwards.
struct Emulation
{
  bool fused = false;
  Index slabSlices = 0;
  bool backwards = false;
};

/// The fused pass as SlabTransfers.h runs it: the block's chunks arrive in the plan's
/// order into device memory that starts poisoned, and slab i runs when chunks 0..i are
/// there; shared memory is poisoned for every block.
template <class T, class Acc>
void runFusedOnHost(const std::vector<T>& block, const vao::gpu::RegionGeometry& g, Acc shift,
  const vao::gpu::EstimatorSetting& estimator, const vao::gpu::FinalOutputs& out, bool withExtrema,
  const Emulation& how)
{
  const Index segment = vao::gpu::segmentLength(g.radius[2]);
  const auto plan =
    vao::gpu::planSlabs(g, how.slabSlices > 0 ? how.slabSlices : vao::gpu::slabSlices(g, segment));
  std::vector<T> device(block.size(), std::numeric_limits<T>::max());
  const vao::gpu::StatisticsWriter<T, Acc> writer{ nullptr, nullptr, device.data(), g, shift,
    estimator, out };
  const Index slice = g.sx * g.sy;
  for (const auto& step : plan)
  {
    std::copy(block.begin() + step.chunkBegin * slice, block.begin() + step.chunkEnd * slice,
      device.begin() + step.chunkBegin * slice);
    if (withExtrema)
      runBlocksOnHost(
        vao::gpu::fusedStatisticsWithExtrema(writer, step.sliceBegin, step.sliceEnd, segment),
        how.backwards);
    else
      runBlocksOnHost(
        vao::gpu::fusedStatistics(writer, step.sliceBegin, step.sliceEnd, segment), how.backwards);
  }
}

/// The pipeline on the host, set up as CudaBackend.cu sets it up on the device.
template <class T>
Results emulate(const std::vector<T>& v, const vao::Index3& dims, const vao::Region& region,
  const vao::Radius& radius, bool statistics, const vao::gpu::EstimatorSetting& estimator,
  const Emulation& how = {})
{
  using Acc = typename vao::detail::MomentTraits<T>::Accumulator;
  const auto g = vao::gpu::geometryFor(dims, region, radius);
  const std::vector<T> block = blockOf(v, dims, region, g);
  const vao::detail::TypedVolume<T> volume(viewOf(v, dims));
  const Acc shift = vao::detail::MomentTraits<T>::exactInteger
    ? Acc(0)
    : static_cast<Acc>(vao::detail::sampledMean(volume));
  Results r;
  const size_t n = static_cast<size_t>(region.voxelCount());
  vao::gpu::FinalOutputs out{};
  const bool withExtrema = statistics || estimator.method == vao::Method::CdfReconstruction;
  if (statistics)
  {
    for (auto* a : { &r.count, &r.mean, &r.varianceD, &r.minimum, &r.maximum })
      a->assign(n, -1.0);
    out = { nullptr, nullptr, r.count.data(), r.mean.data(), r.varianceD.data(), r.minimum.data(),
      r.maximum.data() };
  }
  else
  {
    r.openness.assign(n, -1.0f);
    r.variance.assign(n, -1.0f);
    out = { r.openness.data(), r.variance.data(), nullptr, nullptr, nullptr, nullptr, nullptr };
  }
  if (how.fused)
  {
    runFusedOnHost<T, Acc>(block, g, shift, estimator, out, withExtrema, how);
    return r;
  }
  HostExecutor ex;
  vao::gpu::runPasses<T, Acc>(ex, block.data(), g, withExtrema, shift, estimator, out);
  return r;
}

/// The emulated passes against the CPU library: the statistics (minimum and maximum exact)
/// and the openness of a moment estimator.
template <class T>
void expectStatisticsLikeTheCpu(const std::vector<T>& v, const vao::Index3& dims,
  const vao::Region& region, const vao::Radius& radius, const Emulation& how = {})
{
  const Results gpu = emulate(v, dims, region, radius, true,
    { vao::Method::GaussianCdf, vao::QueryMode::VoxelValue, 0, vao::ErfMode::Exact }, how);
  const size_t n = static_cast<size_t>(region.voxelCount());
  std::vector<double> count(n), mean(n), variance(n), minimum(n), maximum(n);
  ASSERT_TRUE(vao::computeBoxStatistics(viewOf(v, dims), region, radius,
    { count.data(), mean.data(), variance.data(), minimum.data(), maximum.data() })
                .ok);
  for (size_t k = 0; k < n; ++k)
  {
    ASSERT_EQ(gpu.count[k], count[k]) << k;
    ASSERT_EQ(gpu.minimum[k], minimum[k]) << k;
    ASSERT_EQ(gpu.maximum[k], maximum[k]) << k;
    ASSERT_NEAR(gpu.mean[k], mean[k], 1e-9 * std::max(1.0, std::abs(mean[k]))) << k;
    ASSERT_NEAR(gpu.varianceD[k], variance[k], 1e-9 * std::max(1.0, std::abs(variance[k]))) << k;
  }
}

template <class T>
void expectOpennessLikeTheCpu(const std::vector<T>& v, const vao::Index3& dims,
  const vao::Region& region, const vao::Radius& radius, vao::Method method, vao::QueryMode query,
  double iso, const Emulation& how = {})
{
  const Results gpu =
    emulate(v, dims, region, radius, false, { method, query, iso, vao::ErfMode::Exact }, how);
  const size_t n = static_cast<size_t>(region.voxelCount());
  std::vector<float> openness(n), variance(n);
  vao::AmbientOcclusionParameters p;
  p.method = method;
  p.radius = radius;
  p.queryMode = query;
  p.isoValue = iso;
  ASSERT_TRUE(
    vao::computeAmbientOcclusion(viewOf(v, dims), region, p, { openness.data(), variance.data() })
      .ok);
  for (size_t k = 0; k < n; ++k)
  {
    ASSERT_NEAR(gpu.openness[k], openness[k], 1e-6) << "method " << int(method) << " voxel " << k;
    ASSERT_NEAR(gpu.variance[k], variance[k], 1e-6 * std::max(1.0f, std::abs(variance[k]))) << k;
  }
}

} // namespace vaotest
