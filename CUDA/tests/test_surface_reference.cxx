// Surface ambient occlusion and soft shadows against a reference written from docs/methods.md,
// Penner and Mitchell (and the query's documented rules in
// vao/VarianceOcclusionMap.h): its own trilinear weights, estimators and march, on a noisy
// volume (no flat neighbourhood, so the flat rule never decides), anisotropic spacing, an
// origin off zero, unnormalised normals, and point counts around the lane width of the
// implementation. Also the lanes' vector path against their plain loop.
#include "cpu/moment_pyramid/RayBounds.h"
#include "cpu/moment_pyramid/SurfaceLanes.h"
#include "vao/VarianceOcclusionMap.h"

#include "PyramidTestSupport.h"
#include "ReferenceFormulas.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

namespace
{

using vaotest::Vec3;

/// Occluder fraction of q for a level sample: Cantelli's bound or the Gaussian tail.
double refOcclusion(const vao::MomentLevel& level, const Vec3& p, double q, vao::Method estimator)
{
  auto at = [&](const vao::LevelArray& a)
  {
    return [&](std::int64_t x, std::int64_t y, std::int64_t z)
    {
      return static_cast<double>(
        a[static_cast<std::size_t>((z * level.dims[1] + y) * level.dims[0] + x)]);
    };
  };
  const double mu =
    vaotest::reference::trilinear(level.dims, level.origin, level.spacing, p, at(level.mean));
  const double s2 = std::max(0.0,
    vaotest::reference::trilinear(level.dims, level.origin, level.spacing, p, at(level.variance)));
  if (estimator == vao::Method::GaussianCdf)
    return 1.0 - 0.5 * std::erfc(-(q - mu) / std::sqrt(2.0 * s2));
  return q <= mu ? 1.0 : s2 / (s2 + (q - mu) * (q - mu));
}

struct Scene
{
  vao::Index3 dims = { 21, 17, 19 };
  Vec3 origin = { -3.0, 1.5, 10.0 };
  Vec3 spacing = { 0.7, 1.1, 1.6 };
  std::vector<float> values;
  std::vector<vao::MomentLevel> pyramid;
  std::vector<double> points, normals;

  Scene(int levels, int count, unsigned seed)
  {
    std::mt19937 rng(seed);
    std::normal_distribution<double> noise(0.0, 30.0);
    values.resize(static_cast<std::size_t>(dims[0] * dims[1] * dims[2]));
    for (std::int64_t z = 0; z < dims[2]; ++z)
      for (std::int64_t y = 0; y < dims[1]; ++y)
        for (std::int64_t x = 0; x < dims[0]; ++x) // a ball of 400 in 0, plus noise
        {
          const double r = std::hypot(x - 10.0, y - 8.0, z - 9.0);
          values[static_cast<std::size_t>((z * dims[1] + y) * dims[0] + x)] =
            static_cast<float>((r < 6.0 ? 400.0 : 0.0) + noise(rng));
        }
    EXPECT_TRUE(vao::buildMomentPyramid(view(), origin, spacing, { levels, false }, pyramid).ok);
    std::uniform_real_distribution<double> unit(0.0, 1.0), direction(-2.0, 2.0);
    for (int i = 0; i < count; ++i)
    {
      for (int a = 0; a < 3; ++a)
        points.push_back(origin[a] + unit(rng) * (dims[a] - 1) * spacing[a]);
      Vec3 n;
      do
        n = { direction(rng), direction(rng), direction(rng) };
      while (n[0] * n[0] + n[1] * n[1] + n[2] * n[2] < 0.1);
      normals.insert(normals.end(), n.begin(), n.end());
    }
  }

  vao::VolumeView view() const
  {
    vao::VolumeView v;
    v.data = values.data();
    v.type = vao::ScalarType::Float32;
    v.dims = dims;
    return v;
  }

  Vec3 point(int i) const { return { points[3 * i], points[3 * i + 1], points[3 * i + 2] }; }
  Vec3 normal(int i) const
  {
    const double* n = &normals[3 * i];
    const double l = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
    return { n[0] / l, n[1] / l, n[2] / l };
  }
};

Vec3 along(const Vec3& p, const Vec3& n, double d)
{
  return { p[0] + d * n[0], p[1] + d * n[1], p[2] + d * n[2] };
}

double refAo(const Scene& s, int i, const vao::SurfaceOcclusionParameters& p)
{
  const Vec3 x = s.point(i), n = s.normal(i);
  const double h = std::min({ s.spacing[0], s.spacing[1], s.spacing[2] });
  const double q = p.query == vao::SurfaceQuery::IsoValue
    ? p.isoValue
    : vaotest::reference::trilinear(s.dims, s.origin, s.spacing, along(x, n, -h / 2),
        [&](std::int64_t a, std::int64_t b, std::int64_t c)
        {
          return static_cast<double>(
            s.values[static_cast<std::size_t>((c * s.dims[1] + b) * s.dims[0] + a)]);
        });
  const int levels = static_cast<int>(s.pyramid.size());
  double combined = 0.0;
  for (int l = 0; l < levels; ++l)
  {
    const double o = refOcclusion(
      s.pyramid[l], along(x, n, p.offsetFactor * s.pyramid[l].kernelRadius), q, p.estimator);
    combined =
      p.combination == vao::LevelCombination::Mean ? combined + o / levels : std::max(combined, o);
  }
  return 1.0 - std::clamp(combined, 0.0, 1.0);
}

double refShadow(const Scene& s, int i, const Vec3& light, const vao::SurfaceOcclusionParameters& p)
{
  const vao::MomentLevel& base = s.pyramid[0];
  const Vec3 x = s.point(i), n = s.normal(i);
  const double h = std::min({ base.spacing[0], base.spacing[1], base.spacing[2] });
  double q = p.isoValue;
  if (p.query == vao::SurfaceQuery::HalfVoxelInside) // level 0's mean half a voxel inside
  {
    const Vec3 inside = along(x, n, -h / 2);
    q = vaotest::reference::trilinear(base.dims, base.origin, base.spacing, inside,
      [&](std::int64_t a, std::int64_t b, std::int64_t c)
      {
        return static_cast<double>(
          base.mean[static_cast<std::size_t>((c * base.dims[1] + b) * base.dims[0] + a)]);
      });
  }
  const double length = std::sqrt(light[0] * light[0] + light[1] * light[1] + light[2] * light[2]);
  const Vec3 l = { light[0] / length, light[1] / length, light[2] / length };
  const double r0 = base.kernelRadius;
  const Vec3 start = along(x, n, r0);
  const int levels = static_cast<int>(s.pyramid.size());
  double occlusion = 0.0;
  // The distance in units of r0: the steps, half a level's radius (r_l = 2^l r0), add
  // exactly, so the levels change exactly where t / r0 + 1 reaches a power of two.
  for (double u = 0.0;;)
  {
    const double t = u * r0;
    const Vec3 at = along(start, l, t);
    bool inside = true;
    for (int a = 0; a < 3; ++a)
    {
      // The volume's box, faces included to two float32 ulps (surface points are floats).
      const double lo = base.origin[a], hi = base.origin[a] + (base.dims[a] - 1) * base.spacing[a];
      const double slack =
        2.0 * std::numeric_limits<float>::epsilon() * std::max(std::abs(lo), std::abs(hi));
      inside = inside && at[a] >= lo - slack && at[a] <= hi + slack;
    }
    if (!inside)
      break;
    const int level =
      std::clamp(static_cast<int>(std::floor(std::log2(1.0 + u))), 0, levels - 1); // u = t / r0
    occlusion = std::max(occlusion, refOcclusion(s.pyramid[level], at, q, p.estimator));
    if (occlusion >= 0.999)
      break;
    u += std::ldexp(0.5, level);
  }
  return 1.0 - std::clamp(occlusion, 0.0, 1.0);
}

} // namespace

TEST(SurfaceReference, AmbientOcclusionAndShadowsMatchTheDefinition)
{
  int compared = 0;
  for (int count : { 1, 5, 8, 37 })
  {
    const Scene s(count == 37 ? 4 : 3, count, 17u + count);
    // The same queries on a SurfacePyramid (levels 0 and 1 in tiles, kept from query to
    // query) against the same definition.
    vao::SurfacePyramid tiled;
    ASSERT_TRUE(vao::buildSurfacePyramid(
      s.view(), s.origin, s.spacing, { static_cast<int>(s.pyramid.size()), false }, tiled)
                  .ok);
    vaotest::forEachSurfaceQuery(
      [&](vao::SurfaceOcclusionParameters p)
      {
        for (vao::LevelCombination combination :
          { vao::LevelCombination::MaximumOcclusion, vao::LevelCombination::Mean })
        {
          p.isoValue = 150.0;
          p.combination = combination;
          p.offsetFactor = 0.8;
          std::vector<float> ao(count, -1.0f), shadow(count, -1.0f);
          ASSERT_TRUE(vao::surfaceAmbientOcclusion(s.pyramid, s.view(), s.origin, s.spacing,
            s.points.data(), s.normals.data(), count, p, ao.data())
                        .ok);
          const Vec3 light = { 0.3, -1.0, 0.7 };
          ASSERT_TRUE(vao::surfaceShadow(
            s.pyramid, s.points.data(), s.normals.data(), count, light, p, shadow.data())
                        .ok);
          std::vector<float> tiledAo(count, -1.0f), tiledShadow(count, -1.0f);
          ASSERT_TRUE(vao::surfaceAmbientOcclusion(tiled, s.view(), s.origin, s.spacing,
            s.points.data(), s.normals.data(), count, p, tiledAo.data())
                        .ok);
          ASSERT_TRUE(vao::surfaceShadow(
            tiled, s.points.data(), s.normals.data(), count, light, p, tiledShadow.data())
                        .ok);
          for (int i = 0; i < count; ++i)
          {
            EXPECT_NEAR(ao[i], refAo(s, i, p), 2e-5) << "AO, point " << i << " of " << count;
            EXPECT_NEAR(shadow[i], refShadow(s, i, light, p), 2e-5)
              << "shadow, point " << i << " of " << count;
            EXPECT_NEAR(tiledAo[i], refAo(s, i, p), 2e-5)
              << "tiled AO, point " << i << " of " << count;
            EXPECT_NEAR(tiledShadow[i], refShadow(s, i, light, p), 2e-5)
              << "tiled shadow, point " << i << " of " << count;
            ++compared;
          }
        }
      });
  }
  EXPECT_EQ(compared, 8 * (1 + 5 + 8 + 37));
}

TEST(SurfaceLanes, VectorPathEqualsThePlainLoop)
{
  // Positions inside, on the faces and outside (clamped), on levels with a one-voxel axis
  // (x: the cells have no x pair, the vector path gathers corner by corner).
  for (const vao::Index3 dims :
    { vao::Index3{ 9, 7, 5 }, vao::Index3{ 6, 1, 4 }, vao::Index3{ 1, 5, 3 } })
  {
    std::mt19937 rng(5);
    std::uniform_real_distribution<double> value(-50.0, 50.0);
    vao::MomentLevel level = vaotest::smallLevel(dims,
      [&](std::size_t i, float& mean, float& variance)
      {
        mean = static_cast<float>(value(rng));
        variance = i % 5 == 0 ? 0.0f : static_cast<float>(std::fabs(value(rng))); // some flat
      });
    level.roundingVariance = 1e-9;
    const vao::detail::LevelGrid grid(level);
    std::uniform_real_distribution<double> where(-4.0, 16.0);
    int lanesCompared = 0;
    for (int batch = 0; batch < 200; ++batch)
    {
      double x[vao::detail::kLanes], y[vao::detail::kLanes], z[vao::detail::kLanes],
        q[vao::detail::kLanes];
      for (int k = 0; k < vao::detail::kLanes; ++k)
      {
        x[k] = where(rng);
        y[k] = where(rng);
        z[k] = k == 3 ? level.origin[2] + (dims[2] - 1) * level.spacing[2]
                      : where(rng); // on the last face
        q[k] = value(rng);
      }
      double plain[vao::detail::kLanes], vector[vao::detail::kLanes];
      vao::detail::occlusionLanesPlain(grid, vao::Method::Chebyshev, x, y, z, q, plain);
      // Each vector tier (where the processor has it; above, the widest it has).
      for (const vao::detail::SimdTier tier :
        { vao::detail::SimdTier::Avx2, vao::detail::SimdTier::Avx512 })
      {
        vao::detail::limitSimdTier(tier);
        vao::detail::occlusionLanes(grid, vao::Method::Chebyshev, x, y, z, q, vector);
        vao::detail::limitSimdTier(vao::detail::SimdTier::Avx512);
        for (int k = 0; k < vao::detail::kLanes; ++k)
        {
          EXPECT_NEAR(vector[k], plain[k], 1e-12)
            << "lane " << k << ", tier " << static_cast<int>(tier);
          ++lanesCompared;
        }
      }
    }
    EXPECT_EQ(lanesCompared, 2 * 200 * vao::detail::kLanes);
  }
}

TEST(SurfaceLanes, CellBoundsHoldTheLargestCornerValues)
{
  for (const vao::Index3 dims :
    { vao::Index3{ 7, 6, 5 }, vao::Index3{ 1, 4, 3 }, vao::Index3{ 5, 1, 1 } })
  {
    vao::MomentLevel level;
    level.dims = dims;
    const auto n = static_cast<std::size_t>(dims[0] * dims[1] * dims[2]);
    std::mt19937 rng(11);
    std::uniform_real_distribution<double> value(-80.0, 80.0);
    level.mean.resize(n);
    level.variance.resize(n);
    for (std::size_t i = 0; i < n; ++i)
    {
      level.mean[i] = static_cast<float>(value(rng));
      level.variance[i] = static_cast<float>(value(rng)); // negatives: the bound is at least 0
    }
    vao::detail::LevelGrid grid(level);
    const vao::detail::CellBounds bounds(level, grid);
    auto index = [&](std::int64_t x, std::int64_t y, std::int64_t z)
    { return (z * dims[1] + y) * dims[0] + x; };
    for (std::int64_t z = 0; z < dims[2]; ++z)
      for (std::int64_t y = 0; y < dims[1]; ++y)
        for (std::int64_t x = 0; x < dims[0]; ++x)
        {
          float mean = -1e30f, variance = 0.0f;
          for (std::int64_t c = 0; c < 8; ++c) // the cell's corners, clamped to the level
          {
            const std::int64_t i = index(std::min<std::int64_t>(x + (c & 1), dims[0] - 1),
              std::min<std::int64_t>(y + ((c >> 1) & 1), dims[1] - 1),
              std::min<std::int64_t>(z + (c >> 2), dims[2] - 1));
            mean = std::max(mean, level.mean[i]);
            variance = std::max(variance, level.variance[i]);
          }
          EXPECT_EQ(grid.cellBounds[2 * index(x, y, z)], mean) << x << " " << y << " " << z;
          EXPECT_EQ(grid.cellBounds[2 * index(x, y, z) + 1], variance) << x << " " << y << " " << z;
        }
  }
}

#if VAO_HAVE_AVX2_TARGET
TEST(SurfaceLanes, MarchPassingOverBoundedCellsEqualsTheFullMarch)
{
  if (!vao::detail::cpuHasAvx2())
    GTEST_SKIP() << "no AVX2: the vector march does not run here";
  // The scene's ball and noise, plus queries from below the smallest to above the largest
  // means: most cells' bounds fall below what a march already holds.
  const Scene s(4, 0, 23u);
  std::vector<vao::detail::LevelGrid> bare, bounded;
  std::vector<vao::detail::CellBounds> bounds;
  std::vector<double> radius;
  bounds.reserve(s.pyramid.size());
  for (const vao::MomentLevel& level : s.pyramid)
  {
    bare.emplace_back(level);
    bounded.emplace_back(level);
    bounds.emplace_back(level, bounded.back());
    radius.push_back(level.kernelRadius);
  }
  const vao::MomentLevel& base = s.pyramid[0];
  double lo[3], hi[3];
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = base.origin[a];
    hi[a] = base.origin[a] + (base.dims[a] - 1) * base.spacing[a];
  }
  std::mt19937 rng(29);
  std::uniform_real_distribution<double> unit(0.0, 1.0), query(-100.0, 600.0), direction(-1.0, 1.0);
  int lanes = 0, occluded = 0, wideBatches = 0;
  for (int batch = 0; batch < 400; ++batch)
  {
    constexpr int W = vao::detail::kLanes;
    double x[W], y[W], z[W], q[W], full[W], passed[W];
    for (int k = 0; k < W; ++k)
    {
      x[k] = lo[0] + unit(rng) * (hi[0] - lo[0]);
      y[k] = lo[1] + unit(rng) * (hi[1] - lo[1]);
      z[k] = lo[2] + unit(rng) * (hi[2] - lo[2]);
      q[k] = query(rng);
    }
    Vec3 light = { direction(rng), direction(rng), direction(rng) };
    const double length =
      std::sqrt(light[0] * light[0] + light[1] * light[1] + light[2] * light[2]);
    for (double& c : light)
      c /= length;
    const double* start[3] = { x, y, z };
    const int levels = 1 + batch % 4;
    const std::vector<vao::detail::MarchStep> schedule =
      vao::detail::marchSchedule(radius.data(), levels, 1e9);
    using vao::detail::SimdTier;
    vao::detail::chebyshevMarch(
      SimdTier::Avx2, bare.data(), schedule, lo, hi, start, light.data(), q, full);
    vao::detail::chebyshevMarch(
      SimdTier::Avx2, bounded.data(), schedule, lo, hi, start, light.data(), q, passed);
    // Lanes stopped where nothing ahead can raise them: the same maxima.
    const vao::detail::RayBounds rays(
      bounded[levels - 1], vao::detail::kMarchStepFraction * radius[levels - 1], light);
    double stopped[W];
    vao::detail::chebyshevMarch(SimdTier::Avx2, bounded.data(), schedule, lo, hi, start,
      light.data(), q, stopped, rays.data(), levels - 1);
    for (int k = 0; k < W; ++k)
    {
      EXPECT_NEAR(passed[k], full[k], 1e-12) << "batch " << batch << ", lane " << k;
      EXPECT_EQ(stopped[k], passed[k]) << "ray bounds, batch " << batch << ", lane " << k;
      occluded += full[k] > 0.01 && full[k] < 0.99;
      ++lanes;
    }
    // AVX-512 marches the whole batch in one vector with the same operations per lane.
    if (vao::detail::cpuSimdTier() == SimdTier::Avx512)
    {
      double wide[W];
      vao::detail::chebyshevMarch(SimdTier::Avx512, bounded.data(), schedule, lo, hi, start,
        light.data(), q, wide, rays.data(), levels - 1);
      for (int k = 0; k < W; ++k)
        EXPECT_EQ(wide[k], passed[k]) << "AVX-512, batch " << batch << ", lane " << k;
      ++wideBatches;
    }
  }
  EXPECT_TRUE(wideBatches == 0 || wideBatches == 400);
  EXPECT_EQ(lanes, 400 * vao::detail::kLanes);
  EXPECT_GT(occluded, lanes / 4); // partial occlusions: the bounds decide, not the extremes
}
#endif
