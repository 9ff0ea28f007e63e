// Rays (docs/methods.md section 12): its plan covers the sphere once, its reach is what it
// reads (a piece grown by it gives the whole volume's bits), its cost grows like log R,
// and it is open where nothing is opaque. Its accuracy against Exact Rays is measured on
// the real scans (Testing/Python/test_rays_scans.py).
#include "TestVolumes.h"

#include "cpu/ray_casting/RayEstimate.h"
#include "vao/AmbientOcclusion.h"
#include "vao/RayCasting.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <vector>

namespace
{

vao::AmbientOcclusionParameters raysOf(double radius, const std::array<double, 3>& spacing)
{
  vao::AmbientOcclusionParameters p;
  p.method = vao::Method::Rays;
  p.opacity.nodes = { { 20.0, 0.0 }, { 60.0, 0.3 }, { 110.0, 0.9 } };
  p.rays.radius = radius;
  p.rays.spacing = spacing;
  const std::array<int, 3> reach = vao::rayEstimateReach(p.rays);
  p.radius = { reach[0], reach[1], reach[2] };
  return p;
}

std::vector<float> run(const std::vector<float>& values, const vao::Index3& dims,
  const vao::Region& region, const vao::AmbientOcclusionParameters& p, int threads)
{
  std::vector<float> out(static_cast<std::size_t>(region.voxelCount()), -1.0f);
  vao::AmbientOcclusionOutput output;
  output.openness = out.data();
  vao::Execution execution;
  execution.threads = threads;
  const vao::Status status =
    vao::computeAmbientOcclusion(vaotest::viewOf(values, dims), region, p, output, execution);
  EXPECT_TRUE(status.ok) << status.message;
  return out;
}

} // namespace

TEST(Rays, ConesShareTheSphereOnceAndSymmetrically)
{
  for (const auto& spacing : { std::array<double, 3>{ 1.0, 1.0, 1.0 },
         std::array<double, 3>{ 1.41, 1.41, 2.5 }, std::array<double, 3>{ 3.2, 3.2, 1.5 } })
  {
    const vao::detail::RayPlan plan = vao::detail::planRays(raysOf(8.0, spacing).rays);
    ASSERT_EQ(plan.cones.size(), 26u);
    double total = 0.0;
    for (const vao::detail::LatticeCone& cone : plan.cones)
    {
      total += cone.weight;
      // Each cone's opposite has the same share.
      const auto opposite = std::find_if(plan.cones.begin(), plan.cones.end(),
        [&](const vao::detail::LatticeCone& other)
        {
          return other.step[0] == -cone.step[0] && other.step[1] == -cone.step[1] &&
            other.step[2] == -cone.step[2];
        });
      ASSERT_NE(opposite, plan.cones.end());
      EXPECT_EQ(opposite->weight, cone.weight);
      // The near and far samples cover the radius once.
      double covered = 0.0;
      for (const auto& s : cone.near)
        covered += s.length;
      for (const auto& s : cone.far)
        covered += s.length;
      EXPECT_NEAR(covered, 8.0, 1e-9);
    }
    EXPECT_NEAR(total, 1.0, 1e-12);
  }
}

TEST(Rays, FarSamplesGrowLikeTheLogarithmOfTheRadius)
{
  std::size_t at10 = 0, at1000 = 0;
  for (const auto& cone : vao::detail::planRays(raysOf(10.0, { 1.0, 1.0, 1.0 }).rays).cones)
    at10 += cone.far.size();
  for (const auto& cone : vao::detail::planRays(raysOf(1000.0, { 1.0, 1.0, 1.0 }).rays).cones)
    at1000 += cone.far.size();
  EXPECT_LE(at1000, 4 * at10) << at10 << " samples at R = 10, " << at1000 << " at R = 1000";
}

TEST(Rays, PieceGrownByTheReachGivesTheWholeResult)
{
  const vao::Index3 dims = { 30, 26, 22 };
  std::vector<float> values = vaotest::randomVolume<float>(dims, 0.0, 130.0, 11);
  const vao::AmbientOcclusionParameters p = raysOf(5.0, { 1.0, 1.5, 2.0 });
  const std::vector<float> all = run(values, dims, { { 0, 0, 0 }, dims }, p, 2);
  const vao::Index3 lo = { 11, 9, 8 }, size = { 7, 6, 5 };
  const int reach[3] = { p.radius.x, p.radius.y, p.radius.z };
  vao::Index3 blockLo, blockDims;
  for (int a = 0; a < 3; ++a)
  {
    blockLo[a] = std::max<std::int64_t>(0, lo[a] - reach[a]);
    blockDims[a] = std::min<std::int64_t>(dims[a], lo[a] + size[a] + reach[a]) - blockLo[a];
  }
  std::vector<float> block;
  for (std::int64_t z = 0; z < blockDims[2]; ++z)
    for (std::int64_t y = 0; y < blockDims[1]; ++y)
      for (std::int64_t x = 0; x < blockDims[0]; ++x)
        block.push_back(values[static_cast<std::size_t>(
          ((z + blockLo[2]) * dims[1] + y + blockLo[1]) * dims[0] + x + blockLo[0])]);
  const vao::Region region{ { lo[0] - blockLo[0], lo[1] - blockLo[1], lo[2] - blockLo[2] }, size };
  const std::vector<float> piece = run(block, blockDims, region, p, 1);
  for (std::int64_t z = 0; z < size[2]; ++z)
    for (std::int64_t y = 0; y < size[1]; ++y)
      for (std::int64_t x = 0; x < size[0]; ++x)
        ASSERT_EQ(piece[static_cast<std::size_t>((z * size[1] + y) * size[0] + x)],
          all[static_cast<std::size_t>(((z + lo[2]) * dims[1] + y + lo[1]) * dims[0] + x + lo[0])])
          << "voxel " << x << ", " << y << ", " << z << " of the piece";
  // And the reach is not far more than the rays' own.
  const std::array<int, 3> rays = vao::rayReach(p.rays);
  for (int a = 0; a < 3; ++a)
    EXPECT_LE(reach[a], 2 * rays[a] + 3) << "axis " << a;
}

TEST(Rays, OpenWhereNothingIsOpaqueAndDarkInsideOpaqueMaterial)
{
  const vao::Index3 dims = { 21, 21, 21 };
  std::vector<float> values(static_cast<std::size_t>(dims[0] * dims[1] * dims[2]), 0.0f);
  vao::AmbientOcclusionParameters p = raysOf(4.0, { 1.0, 1.0, 1.0 });
  for (const float v : run(values, dims, { { 0, 0, 0 }, dims }, p, 0))
    ASSERT_EQ(v, 1.0f);
  // Everything at opacity 0.9 per voxel: the middle sees (almost) nothing.
  std::fill(values.begin(), values.end(), 110.0f);
  const std::vector<float> dark = run(values, dims, { { 0, 0, 0 }, dims }, p, 0);
  EXPECT_LT(dark[(10 * 21 + 10) * 21 + 10], 0.01f);
  // A corner sees the open sky of 7/8 of the sphere at least.
  EXPECT_GT(dark[0], 0.8f);
}
