// Allocation failure inside the kernels' entry points: a std::bad_alloc from any buffer a
// call makes comes back as a Status that says memory, never as an exception. This test
// binary replaces the global operator new (every std::vector in the library goes through
// it) with one that can be told to fail from a size on; until told, it is malloc.
#include "PyramidTestSupport.h"

#include "cpu/simd/CpuDispatch.h"
#include "vao/BlockSweeping.h"
#include "vao/HistogramCdf.h"
#include "vao/OcclusionSweeping.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <functional>
#include <new>
#include <string>
#include <vector>

namespace
{
std::atomic<std::size_t> gFailFrom{ 0 }; // 0: every allocation is served

/// While alive, every operator new of `bytes` or more throws std::bad_alloc.
class FailingAllocations
{
public:
  explicit FailingAllocations(std::size_t bytes) { gFailFrom.store(bytes); }
  ~FailingAllocations() { gFailFrom.store(0); }
};
}

// Every unaligned form, so that each allocation and its release meet in malloc and free
// (a sanitizer's runtime supplies the forms not replaced here, with its own bookkeeping).
void* operator new(std::size_t size)
{
  const std::size_t from = gFailFrom.load(std::memory_order_relaxed);
  if (from != 0 && size >= from)
    throw std::bad_alloc();
  if (void* p = std::malloc(size != 0 ? size : 1))
    return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t size)
{
  return operator new(size);
}
void* operator new(std::size_t size, const std::nothrow_t&) noexcept
{
  try
  {
    return operator new(size);
  }
  catch (const std::bad_alloc&)
  {
    return nullptr;
  }
}
void* operator new[](std::size_t size, const std::nothrow_t& tag) noexcept
{
  return operator new(size, tag);
}
void operator delete(void* p) noexcept
{
  std::free(p);
}
void operator delete[](void* p) noexcept
{
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept
{
  std::free(p);
}
void operator delete[](void* p, std::size_t) noexcept
{
  std::free(p);
}
void operator delete(void* p, const std::nothrow_t&) noexcept
{
  std::free(p);
}
void operator delete[](void* p, const std::nothrow_t&) noexcept
{
  std::free(p);
}

using namespace vaotest;

namespace
{
/// A ball of radius 12 in 64^3, its pyramid, and as many points on its surface as level 0
/// has voxels: enough that the shadow march bounds the cells of every level (on level 0,
/// 2 MB of float pairs) when it runs on vectors.
struct BallScene
{
  Field field;
  std::vector<vao::MomentLevel> pyramid;
  std::vector<double> points, normals;
  std::int64_t count = 64 * 64 * 64;

  BallScene()
    : field(makeField({ 64, 64, 64 },
        [](double x, double y, double z)
        {
          return std::sqrt(
                   (x - 31.5) * (x - 31.5) + (y - 31.5) * (y - 31.5) + (z - 31.5) * (z - 31.5)) -
            12.0;
        }))
    , pyramid(pyramidOf(field))
  {
    spherePoints(
      { 31.5, 31.5, 31.5 }, 12.0, static_cast<int>(this->count), this->points, this->normals);
  }
};

/// A shortage reported: "not enough memory for ...", or where even that message could not
/// be had (every allocation refused), the short "out of memory".
void expectShortage(const vao::Status& s)
{
  EXPECT_FALSE(s.ok);
  EXPECT_TRUE(s.outOfMemory) << s.message;
  EXPECT_TRUE(s.message.find("not enough memory for ") == 0 || s.message == "out of memory")
    << s.message;
}
}

TEST(OutOfMemory, AllocationsFailOnlyWhileTold)
{
  {
    FailingAllocations failing(1024);
    EXPECT_THROW(std::vector<char>(4096), std::bad_alloc);
    EXPECT_NO_THROW(std::vector<char>(512));
  }
  EXPECT_NO_THROW(std::vector<char>(1 << 20));
}

TEST(OutOfMemory, TheStatusSaysSoEvenWhenNothingCanBeAllocated)
{
  const std::string what = "the buffers";
  vao::Status s = vao::Status::noMemory(what);
  EXPECT_EQ(s.message, "not enough memory for the buffers");
  EXPECT_TRUE(s.outOfMemory);
  EXPECT_FALSE(s.ok);
  {
    FailingAllocations failing(1);
    s = vao::Status::noMemory("the buffers");
  }
  EXPECT_EQ(s.message, "out of memory");
  EXPECT_TRUE(s.outOfMemory);
  EXPECT_FALSE(s.ok);
}

TEST(OutOfMemory, ShadowsOnWholeLevelsReportIt)
{
  const BallScene scene;
  std::vector<float> shadow(scene.count, -1.0f), again(scene.count, -2.0f);
  const std::array<double, 3> light = { 0.0, 0.6, 0.8 };
  const vao::Status first = vao::surfaceShadow(scene.pyramid, scene.points.data(),
    scene.normals.data(), scene.count, light, {}, shadow.data());
  ASSERT_TRUE(first.ok) << first.message;
  if (vao::detail::cpuSimdTier() < vao::detail::SimdTier::Avx2)
    GTEST_SKIP() << "the scalar march makes no cell bounds: nothing of this size to refuse";
  {
    FailingAllocations failing(1 << 20);
    expectShortage(vao::surfaceShadow(scene.pyramid, scene.points.data(), scene.normals.data(),
      scene.count, light, {}, again.data()));
  }
  // The same call succeeds afterwards, with the same values.
  ASSERT_TRUE(vao::surfaceShadow(
    scene.pyramid, scene.points.data(), scene.normals.data(), scene.count, light, {}, again.data())
                .ok);
  EXPECT_EQ(shadow, again);
}

TEST(OutOfMemory, SurfacePyramidQueriesReportIt)
{
  // A SurfacePyramid builds tiles of 2 kB (level 0) as the query reaches them: refusing
  // every allocation of a page or more refuses the tiles' pool and the sweep's order.
  const BallScene scene;
  vao::SurfacePyramid tiled;
  ASSERT_TRUE(
    vao::buildSurfacePyramid(scene.field.view(), scene.field.origin, scene.field.spacing, {}, tiled)
      .ok);
  std::vector<float> out(scene.count, -1.0f);
  {
    FailingAllocations failing(4096);
    expectShortage(vao::surfaceAmbientOcclusion(tiled, scene.field.view(), scene.field.origin,
      scene.field.spacing, scene.points.data(), scene.normals.data(), scene.count, {}, out.data()));
    expectShortage(vao::surfaceShadow(
      tiled, scene.points.data(), scene.normals.data(), scene.count, { 0, 0, 1 }, {}, out.data()));
  }
  EXPECT_TRUE(vao::surfaceShadow(
    tiled, scene.points.data(), scene.normals.data(), scene.count, { 0, 0, 1 }, {}, out.data())
                .ok);
}

namespace
{
/// One entry point on a fixed input: run(out) writes its results (floats) into `out`.
struct EntryPoint
{
  const char* name;
  std::size_t size; // floats of `out`, which the caller sizes (run allocates none of its own)
  std::function<vao::Status(std::vector<float>& out)> run;
};

/// A 40 x 36 x 30 int16 volume of two materials with noise, and its float copy.
struct SmallVolumes
{
  vao::Index3 dims = { 40, 36, 30 };
  std::vector<std::int16_t> ct;
  std::vector<float> density;

  SmallVolumes()
  {
    const std::int64_t n = dims[0] * dims[1] * dims[2];
    ct.resize(n);
    density.resize(n);
    std::uint32_t s = 12345;
    for (std::int64_t i = 0; i < n; ++i)
    {
      const std::int64_t x = i % dims[0], y = i / dims[0] % dims[1], z = i / (dims[0] * dims[1]);
      const double r =
        std::sqrt(double((x - 20) * (x - 20) + (y - 18) * (y - 18) + (z - 15) * (z - 15)));
      s = s * 1664525u + 1013904223u;
      ct[i] = static_cast<std::int16_t>((r < 11 ? 1200 : -900) + int(s >> 24) - 128);
      density[i] = r < 11 ? 1.0f : 0.0f;
    }
  }
  vao::VolumeView ctView() const { return viewOf(ct, dims); }
  vao::VolumeView densityView() const { return viewOf(density, dims); }
};
}

// Every entry point, with every allocation from a size on refused (from the smallest to
// none): it returns a Status, never throws, and either says "not enough memory" or gives
// the results of an unrefused run.
TEST(OutOfMemory, EveryEntryPointReportsItOrSucceeds)
{
  const SmallVolumes v;
  const std::int64_t n = v.dims[0] * v.dims[1] * v.dims[2];
  const std::array<double, 3> origin = { 0, 0, 0 }, spacing = { 1, 1, 1 };
  std::vector<double> points, normals;
  spherePoints({ 20, 18, 15 }, 11.0, 500, points, normals);
  std::vector<EntryPoint> entries;
  const auto openness = [&](vao::Method method, vao::QueryMode query)
  {
    return [&, method, query](std::vector<float>& out)
    {
      vao::AmbientOcclusionParameters p;
      p.method = method;
      p.radius = { 3, 3, 3 };
      p.queryMode = query;
      p.isoValue = 300.0;
      if (method == vao::Method::HistogramCdf)
      {
        const vao::Status s = vao::volumeThresholds(v.ctView(), 16, p.thresholds);
        if (!s.ok)
          return s;
      }
      std::fill(out.begin(), out.end(), -1.0f);
      return vao::computeAmbientOcclusion(
        v.ctView(), vao::Region::whole(v.ctView()), p, { out.data(), out.data() + n });
    };
  };
  for (const vao::Method m :
    { vao::Method::CdfReconstruction, vao::Method::GaussianCdf, vao::Method::Chebyshev,
      vao::Method::ExactBox, vao::Method::ExactSphere, vao::Method::HistogramCdf })
    entries.push_back(
      { "computeAmbientOcclusion", std::size_t(2 * n), openness(m, vao::QueryMode::VoxelValue) });
  entries.push_back({ "computeAmbientOcclusion, smoothed query", std::size_t(2 * n),
    openness(vao::Method::GaussianCdf, vao::QueryMode::SmoothedValue) });
  std::vector<double> stats(5 * n);
  entries.push_back({ "computeBoxStatistics", std::size_t(5 * n),
    [&](std::vector<float>& out)
    {
      std::fill(stats.begin(), stats.end(), -1.0);
      const vao::Status s =
        vao::computeBoxStatistics(v.ctView(), vao::Region::whole(v.ctView()), { 2, 3, 4 },
          { stats.data(), stats.data() + n, stats.data() + 2 * n, stats.data() + 3 * n,
            stats.data() + 4 * n });
      std::copy(stats.begin(), stats.end(), out.begin());
      return s;
    } });
  entries.push_back({ "computeOcclusionSweeping", std::size_t(10 * n),
    [&](std::vector<float>& out)
    {
      std::fill(out.begin(), out.end(), -1.0f);
      vao::SweepParameters p;
      p.isoValue = 0.5;
      return vao::computeOcclusionSweeping(
        v.densityView(), spacing, p, { out.data(), out.data() + n, out.data() + 2 * n });
    } });
  entries.push_back({ "BlockSweeper", std::size_t(10 * n),
    [&](std::vector<float>& out)
    {
      std::fill(out.begin(), out.end(), -1.0f);
      vao::SweepParameters p;
      p.isoValue = 0.5;
      vao::BlockPlacement whole;
      whole.whole = whole.size = v.dims;
      vao::BlockSweeper sweeper(v.densityView(), whole, spacing, p);
      vao::Status s = sweeper.initialise();
      if (s.ok)
        s = sweeper.runRound(1);
      if (s.ok)
        s = sweeper.finish({ out.data(), out.data() + n, out.data() + 2 * n });
      return s;
    } });
  const auto surface = [&](bool tiled, bool shadow)
  {
    return [&, tiled, shadow](std::vector<float>& out)
    {
      std::fill(out.begin(), out.end(), -1.0f);
      const std::int64_t count = static_cast<std::int64_t>(out.size());
      // The query on either form of the pyramid (each overload takes it first).
      const auto query = [&](auto& pyramid)
      {
        return shadow ? vao::surfaceShadow(pyramid, points.data(), normals.data(), count,
                          { 0, 0, 1 }, {}, out.data())
                      : vao::surfaceAmbientOcclusion(pyramid, v.ctView(), origin, spacing,
                          points.data(), normals.data(), count, {}, out.data());
      };
      if (tiled)
      {
        vao::SurfacePyramid pyramid;
        const vao::Status s = vao::buildSurfacePyramid(v.ctView(), origin, spacing, {}, pyramid);
        return s.ok ? query(pyramid) : s;
      }
      std::vector<vao::MomentLevel> pyramid;
      const vao::Status s = vao::buildMomentPyramid(v.ctView(), origin, spacing, {}, pyramid);
      return s.ok ? query(pyramid) : s;
    };
  };
  entries.push_back(
    { "buildMomentPyramid + surfaceAmbientOcclusion", points.size() / 3, surface(false, false) });
  entries.push_back(
    { "buildMomentPyramid + surfaceShadow", points.size() / 3, surface(false, true) });
  entries.push_back(
    { "buildSurfacePyramid + surfaceAmbientOcclusion", points.size() / 3, surface(true, false) });
  entries.push_back(
    { "buildSurfacePyramid + surfaceShadow", points.size() / 3, surface(true, true) });

  for (std::size_t e = 0; e < entries.size(); ++e)
  {
    SCOPED_TRACE(std::string(entries[e].name) + " (entry " + std::to_string(e) + ")");
    std::vector<float> expected(entries[e].size), out(entries[e].size);
    const vao::Status free = entries[e].run(expected);
    ASSERT_TRUE(free.ok) << free.message;
    std::size_t refused = 0;
    for (const std::size_t from : { std::size_t(1), std::size_t(64), std::size_t(1024),
           std::size_t(16384), std::size_t(262144), std::size_t(4 << 20) })
    {
      SCOPED_TRACE("allocations of " + std::to_string(from) + " bytes and more refused");
      vao::Status s;
      bool threw = false;
      {
        FailingAllocations failing(from);
        try
        {
          s = entries[e].run(out);
        }
        catch (...) // noted only: the message would allocate while allocations fail
        {
          threw = true;
        }
      }
      ASSERT_FALSE(threw) << "an exception escaped the entry point";
      if (s.ok)
      {
        EXPECT_TRUE(std::equal(expected.begin(), expected.end(), out.begin(), out.end(),
          [](float a, float b) { return a == b || (std::isnan(a) && std::isnan(b)); }));
        continue;
      }
      ++refused;
      expectShortage(s);
    }
    EXPECT_GT(refused, 0u) << "no refusal reached the call: the test proves nothing for it";
  }
}
