// Allocation failure inside the kernels' entry points: a std::bad_alloc from any buffer a
// call makes comes back as a Status that says memory, never as an exception. This test
// binary replaces the global operator new (every std::vector in the library goes through
// it) with one that can be told to fail from a size on; until told, it is malloc.
#include "PyramidTestSupport.h"

#include "cpu/CpuDispatch.h"

#include <atomic>
#include <cstdlib>
#include <new>
#include <string>

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

void* operator new(std::size_t size)
{
  const std::size_t from = gFailFrom.load(std::memory_order_relaxed);
  if (from != 0 && size >= from)
    throw std::bad_alloc();
  if (void* p = std::malloc(size != 0 ? size : 1))
    return p;
  throw std::bad_alloc();
}
void operator delete(void* p) noexcept
{
  std::free(p);
}
void operator delete(void* p, std::size_t) noexcept
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
    : field(makeField({ 64, 64, 64 }, [](double x, double y, double z) {
      return std::sqrt((x - 31.5) * (x - 31.5) + (y - 31.5) * (y - 31.5) + (z - 31.5) * (z - 31.5)) - 12.0;
    }))
    , pyramid(pyramidOf(field))
  {
    spherePoints({ 31.5, 31.5, 31.5 }, 12.0, static_cast<int>(this->count), this->points, this->normals);
  }
};

void expectShortage(const vao::Status& s)
{
  EXPECT_FALSE(s.ok);
  EXPECT_TRUE(s.outOfMemory) << s.message;
  EXPECT_NE(s.message.find("not enough memory"), std::string::npos) << s.message;
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

TEST(OutOfMemory, ShadowsOnWholeLevelsReportIt)
{
  const BallScene scene;
  std::vector<float> shadow(scene.count, -1.0f), again(scene.count, -2.0f);
  const std::array<double, 3> light = { 0.0, 0.6, 0.8 };
  const vao::Status first =
    vao::surfaceShadow(scene.pyramid, scene.points.data(), scene.normals.data(), scene.count, light, {}, shadow.data());
  ASSERT_TRUE(first.ok) << first.message;
  if (vao::detail::cpuSimdTier() < vao::detail::SimdTier::Avx2)
    GTEST_SKIP() << "the scalar march makes no cell bounds: nothing of this size to refuse";
  {
    FailingAllocations failing(1 << 20);
    expectShortage(
      vao::surfaceShadow(scene.pyramid, scene.points.data(), scene.normals.data(), scene.count, light, {}, again.data()));
  }
  // The same call succeeds afterwards, with the same values.
  ASSERT_TRUE(
    vao::surfaceShadow(scene.pyramid, scene.points.data(), scene.normals.data(), scene.count, light, {}, again.data())
      .ok);
  EXPECT_EQ(shadow, again);
}

TEST(OutOfMemory, SurfacePyramidQueriesReportIt)
{
  // A SurfacePyramid builds tiles of 2 kB (level 0) as the query reaches them: refusing
  // every allocation of a page or more refuses the tiles' pool and the sweep's order.
  const BallScene scene;
  vao::SurfacePyramid tiled;
  ASSERT_TRUE(vao::buildSurfacePyramid(scene.field.view(), scene.field.origin, scene.field.spacing, {}, tiled).ok);
  std::vector<float> out(scene.count, -1.0f);
  {
    FailingAllocations failing(4096);
    expectShortage(vao::surfaceAmbientOcclusion(tiled, scene.field.view(), scene.field.origin, scene.field.spacing,
      scene.points.data(), scene.normals.data(), scene.count, {}, out.data()));
    expectShortage(
      vao::surfaceShadow(tiled, scene.points.data(), scene.normals.data(), scene.count, { 0, 0, 1 }, {}, out.data()));
  }
  EXPECT_TRUE(vao::surfaceShadow(tiled, scene.points.data(), scene.normals.data(), scene.count, { 0, 0, 1 }, {}, out.data()).ok);
}
