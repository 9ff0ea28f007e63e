// Variance occlusion maps (Penner & Mitchell 2008): the moment pyramid against a brute-force
// blur and decimation in double, its precision on large offsets, the surface ambient
// occlusion of analytic scenes, the two-valued exactness of the Chebyshev estimate, the
// soft shadows of a slab, and the validation of the arguments.
#include "TestVolumes.h"
#include "vao/VarianceOcclusionMap.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>

using namespace vaotest;

namespace
{

using Vec3 = std::array<double, 3>;

// ---------------------------------------------------------------------------------------
// Brute-force reference: clipped, renormalised 5x5x5 Gaussian (sigma = 1 voxel) in double,
// evaluated everywhere, then decimation by 2.

struct RefLevel
{
  vao::Index3 dims;
  std::vector<double> m1, m2;
};

RefLevel refBlur(const RefLevel& in)
{
  const vao::Index3 d = in.dims;
  RefLevel out{ d, std::vector<double>(in.m1.size()), std::vector<double>(in.m1.size()) };
  for (std::int64_t z = 0; z < d[2]; ++z)
    for (std::int64_t y = 0; y < d[1]; ++y)
      for (std::int64_t x = 0; x < d[0]; ++x)
      {
        double s1 = 0, s2 = 0, sw = 0;
        for (int k = -2; k <= 2; ++k)
          for (int j = -2; j <= 2; ++j)
            for (int i = -2; i <= 2; ++i)
            {
              const std::int64_t X = x + i, Y = y + j, Z = z + k;
              if (X < 0 || Y < 0 || Z < 0 || X >= d[0] || Y >= d[1] || Z >= d[2])
                continue;
              const double w = std::exp(-0.5 * (i * i + j * j + k * k));
              const std::int64_t idx = (Z * d[1] + Y) * d[0] + X;
              s1 += w * in.m1[idx];
              s2 += w * in.m2[idx];
              sw += w;
            }
        const std::int64_t idx = (z * d[1] + y) * d[0] + x;
        out.m1[idx] = s1 / sw;
        out.m2[idx] = s2 / sw;
      }
  return out;
}

RefLevel refDecimate(const RefLevel& in)
{
  const vao::Index3 d = in.dims;
  const vao::Index3 m = { (d[0] + 1) / 2, (d[1] + 1) / 2, (d[2] + 1) / 2 };
  RefLevel out{ m, std::vector<double>(m[0] * m[1] * m[2]), std::vector<double>(m[0] * m[1] * m[2]) };
  for (std::int64_t z = 0; z < m[2]; ++z)
    for (std::int64_t y = 0; y < m[1]; ++y)
      for (std::int64_t x = 0; x < m[0]; ++x)
      {
        const std::int64_t o = (z * m[1] + y) * m[0] + x;
        const std::int64_t i = ((2 * z) * d[1] + 2 * y) * d[0] + 2 * x;
        out.m1[o] = in.m1[i];
        out.m2[o] = in.m2[i];
      }
  return out;
}

/// Levels of the reference pyramid; moments taken about `shift` (exact in double).
template <class T>
std::vector<RefLevel> refPyramid(
  const std::vector<T>& v, const vao::Index3& d, int levels, bool half, double shift)
{
  RefLevel raw{ d, std::vector<double>(v.size()), std::vector<double>(v.size()) };
  for (std::size_t i = 0; i < v.size(); ++i)
  {
    const double x = static_cast<double>(v[i]) - shift;
    raw.m1[i] = x;
    raw.m2[i] = x * x;
  }
  std::vector<RefLevel> out;
  RefLevel current = refBlur(raw);
  if (half)
    current = refDecimate(current);
  out.push_back(current);
  for (int l = 1; l < levels; ++l)
  {
    current = refDecimate(refBlur(current));
    out.push_back(current);
  }
  return out;
}

void expectLevelsMatch(const std::vector<vao::MomentLevel>& pyramid, const std::vector<RefLevel>& ref,
  double shift, double meanTol, double varTol, double varAbs)
{
  ASSERT_EQ(pyramid.size(), ref.size());
  for (std::size_t l = 0; l < ref.size(); ++l)
  {
    ASSERT_EQ(pyramid[l].dims, ref[l].dims) << "level " << l;
    for (std::size_t i = 0; i < ref[l].m1.size(); ++i)
    {
      const double mean = ref[l].m1[i] + shift;
      const double variance = std::max(0.0, ref[l].m2[i] - ref[l].m1[i] * ref[l].m1[i]);
      ASSERT_NEAR(pyramid[l].mean[i], mean, meanTol * std::max(1.0, std::fabs(mean)))
        << "level " << l << " voxel " << i;
      ASSERT_NEAR(pyramid[l].variance[i], variance, varTol * std::fabs(variance) + varAbs)
        << "level " << l << " voxel " << i;
    }
  }
}

// ---------------------------------------------------------------------------------------
// Scenes

struct Field
{
  vao::Index3 dims;
  Vec3 origin{ 0, 0, 0 };
  Vec3 spacing{ 1, 1, 1 };
  std::vector<float> values;
  vao::VolumeView view() const { return viewOf(values, dims); }
};

/// Occupancy-like density of a signed distance (negative inside): 1 inside, 0 outside,
/// linear across one voxel.
Field makeField(const vao::Index3& dims, const std::function<double(double, double, double)>& sdf)
{
  Field f{ dims, { 0, 0, 0 }, { 1, 1, 1 }, std::vector<float>(dims[0] * dims[1] * dims[2]) };
  for (std::int64_t z = 0; z < dims[2]; ++z)
    for (std::int64_t y = 0; y < dims[1]; ++y)
      for (std::int64_t x = 0; x < dims[0]; ++x)
        f.values[(z * dims[1] + y) * dims[0] + x] =
          static_cast<float>(std::min(1.0, std::max(0.0, 0.5 - sdf(x, y, z))));
  return f;
}

std::vector<vao::MomentLevel> pyramidOf(const Field& f, int levels = 4)
{
  std::vector<vao::MomentLevel> pyramid;
  vao::PyramidParameters p;
  p.levels = levels;
  const vao::Status s = vao::buildMomentPyramid(f.view(), f.origin, f.spacing, p, pyramid);
  EXPECT_TRUE(s.ok) << s.message;
  return pyramid;
}

std::vector<float> ao(const Field& f, const std::vector<vao::MomentLevel>& pyramid,
  const std::vector<double>& points, const std::vector<double>& normals,
  const vao::SurfaceOcclusionParameters& p = {})
{
  std::vector<float> out(points.size() / 3, -1.0f);
  const vao::Status s = vao::surfaceAmbientOcclusion(pyramid, f.view(), f.origin, f.spacing,
    points.data(), normals.data(), static_cast<std::int64_t>(out.size()), p, out.data());
  EXPECT_TRUE(s.ok) << s.message;
  return out;
}

/// Points on a sphere (Fibonacci lattice) and their outward normals.
void spherePoints(const Vec3& c, double r, int n, std::vector<double>& points, std::vector<double>& normals)
{
  const double golden = 3.14159265358979323846 * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i)
  {
    const double z = 1.0 - 2.0 * (i + 0.5) / n;
    const double rho = std::sqrt(1.0 - z * z);
    const Vec3 dir = { rho * std::cos(golden * i), rho * std::sin(golden * i), z };
    for (int a = 0; a < 3; ++a)
    {
      points.push_back(c[a] + r * dir[a]);
      normals.push_back(dir[a]);
    }
  }
}

double average(const std::vector<float>& v)
{
  double s = 0;
  for (float x : v)
    s += x;
  return s / v.size();
}

} // namespace

// ---------------------------------------------------------------------------------------
// Pyramid

TEST(PyramidLevels, MatchBruteForceBlurAndDecimation)
{
  const vao::Index3 d = { 21, 17, 13 };
  const auto v = randomVolume<float>(d, -3.0, 7.0, 11u);
  const Vec3 origin = { 1.5, -2.0, 0.25 };
  const Vec3 spacing = { 0.5, 0.75, 1.25 };
  for (bool half : { false, true })
  {
    vao::PyramidParameters p;
    p.levels = 3;
    p.startAtHalfResolution = half;
    std::vector<vao::MomentLevel> pyramid;
    const vao::Status s = vao::buildMomentPyramid(viewOf(v, d), origin, spacing, p, pyramid);
    ASSERT_TRUE(s.ok) << s.message;
    const auto ref = refPyramid(v, d, 3, half, 0.0);
    expectLevelsMatch(pyramid, ref, 0.0, 1e-5, 1e-4, 1e-6);
    for (int l = 0; l < 3; ++l)
    {
      const double factor = std::ldexp(1.0, l + (half ? 1 : 0));
      for (int a = 0; a < 3; ++a)
      {
        EXPECT_EQ(pyramid[l].origin[a], origin[a]);
        EXPECT_EQ(pyramid[l].spacing[a], spacing[a] * factor);
      }
      EXPECT_EQ(pyramid[l].kernelRadius, 2.0 * 1.25 * factor);
    }
  }
}

TEST(PyramidLevels, IntegerTypesAndStrides)
{
  const vao::Index3 d = { 9, 11, 10 };
  const auto v = randomVolume<std::int16_t>(d, -1000, 2000, 5u);
  // Interleave with a second component to read through a stride.
  std::vector<std::int16_t> two(v.size() * 2);
  for (std::size_t i = 0; i < v.size(); ++i)
  {
    two[2 * i] = static_cast<std::int16_t>(-v[i]);
    two[2 * i + 1] = v[i];
  }
  vao::VolumeView view = viewOf(two, d, 2);
  view.data = two.data() + 1;
  vao::PyramidParameters p;
  p.levels = 3;
  std::vector<vao::MomentLevel> pyramid;
  const vao::Status s = vao::buildMomentPyramid(view, { 0, 0, 0 }, { 1, 1, 1 }, p, pyramid);
  ASSERT_TRUE(s.ok) << s.message;
  expectLevelsMatch(pyramid, refPyramid(v, d, 3, false, 0.0), 0.0, 1e-5, 1e-4, 1e-3);
}

TEST(PyramidLevels, ConstantVolumeStaysConstant)
{
  const vao::Index3 d = { 7, 6, 5 };
  const std::vector<std::uint8_t> v(d[0] * d[1] * d[2], 200);
  vao::PyramidParameters p;
  p.levels = 3;
  std::vector<vao::MomentLevel> pyramid;
  ASSERT_TRUE(vao::buildMomentPyramid(viewOf(v, d), { 0, 0, 0 }, { 1, 1, 1 }, p, pyramid).ok);
  for (const auto& level : pyramid)
    for (std::size_t i = 0; i < level.mean.size(); ++i)
    {
      ASSERT_FLOAT_EQ(level.mean[i], 200.0f);
      ASSERT_EQ(level.variance[i], 0.0f);
    }
  EXPECT_EQ(pyramid[2].dims, (vao::Index3{ 2, 2, 2 }));
}

TEST(PyramidPrecision, LargeOffsetWithUnitNoise)
{
  const vao::Index3 d = { 20, 18, 16 };
  std::mt19937_64 rng(3);
  std::normal_distribution<double> noise(0.0, 1.0);
  std::vector<float> v(d[0] * d[1] * d[2]);
  for (auto& x : v)
    x = static_cast<float>(1e6 + noise(rng));
  vao::PyramidParameters p;
  p.levels = 2;
  std::vector<vao::MomentLevel> pyramid;
  ASSERT_TRUE(vao::buildMomentPyramid(viewOf(v, d), { 0, 0, 0 }, { 1, 1, 1 }, p, pyramid).ok);
  // The reference shifts by an exact 1e6 (the float inputs are exact in double).
  const auto ref = refPyramid(v, d, 2, false, 1e6);
  double largestError = 0.0;
  for (std::size_t i = 0; i < ref[0].m1.size(); ++i)
  {
    const double variance = ref[0].m2[i] - ref[0].m1[i] * ref[0].m1[i];
    largestError = std::max(largestError, std::fabs(pyramid[0].variance[i] - variance));
  }
  EXPECT_LT(largestError, 1e-3);
}

TEST(PyramidSampling, TrilinearAndClamped)
{
  vao::MomentLevel level;
  level.dims = { 3, 4, 5 };
  level.origin = { 1, 2, 3 };
  level.spacing = { 2, 1, 0.5 };
  level.kernelRadius = 4;
  level.mean.resize(60);
  level.variance.resize(60);
  for (std::int64_t z = 0, i = 0; z < 5; ++z)
    for (std::int64_t y = 0; y < 4; ++y)
      for (std::int64_t x = 0; x < 3; ++x, ++i)
      {
        level.mean[i] = static_cast<float>(x + 10 * y + 100 * z);
        level.variance[i] = static_cast<float>(2 * x);
      }
  double mean = 0, variance = 0;
  vao::sampleLevel(level, { 2.0, 3.5, 3.75 }, mean, variance); // index (0.5, 1.5, 1.5)
  EXPECT_NEAR(mean, 0.5 + 15 + 150, 1e-9);
  EXPECT_NEAR(variance, 1.0, 1e-9);
  vao::sampleLevel(level, { -100.0, 100.0, 3.0 }, mean, variance); // clamped to (0, 3, 0)
  EXPECT_NEAR(mean, 30.0, 1e-9);
}

TEST(PyramidSampling, VolumeTrilinearAndClamped)
{
  const vao::Index3 d = { 4, 3, 5 };
  std::vector<std::int16_t> v;
  for (std::int64_t z = 0; z < d[2]; ++z)
    for (std::int64_t y = 0; y < d[1]; ++y)
      for (std::int64_t x = 0; x < d[0]; ++x)
        v.push_back(static_cast<std::int16_t>(x + 10 * y + 100 * z));
  const Vec3 origin = { -1, 0, 2 }, spacing = { 0.5, 2, 1 };
  EXPECT_NEAR(vao::sampleVolume(viewOf(v, d), origin, spacing, { -0.25, 3.0, 4.5 }), 1.5 + 15 + 250, 1e-9); // index (1.5, 1.5, 2.5)
  EXPECT_NEAR(vao::sampleVolume(viewOf(v, d), origin, spacing, { 100.0, -5.0, 0.0 }), 3.0, 1e-9);
}

TEST(PyramidValidation, BadInputFailsWithMessage)
{
  const vao::Index3 d = { 6, 6, 6 };
  std::vector<float> v(216, 1.0f);
  std::vector<vao::MomentLevel> pyramid;
  const vao::PyramidParameters ok;
  auto expectFail = [&](const vao::VolumeView& view, const Vec3& spacing, const vao::PyramidParameters& p) {
    const vao::Status s = vao::buildMomentPyramid(view, { 0, 0, 0 }, spacing, p, pyramid);
    EXPECT_FALSE(s.ok);
    EXPECT_FALSE(s.message.empty());
  };
  expectFail(viewOf(v, { 6, 36, 1 }), { 1, 1, 1 }, ok);                              // 2-D
  expectFail(viewOf(v, d), { 1, 0, 1 }, ok);                                         // zero spacing
  expectFail(viewOf(v, d), { 1, std::numeric_limits<double>::infinity(), 1 }, ok);   // inf spacing
  vao::PyramidParameters p = ok;
  p.levels = 0;
  expectFail(viewOf(v, d), { 1, 1, 1 }, p);
  p.levels = 17;
  expectFail(viewOf(v, d), { 1, 1, 1 }, p);
  v[100] = std::numeric_limits<float>::quiet_NaN();
  expectFail(viewOf(v, d), { 1, 1, 1 }, ok);
  const vao::Status s = vao::buildMomentPyramid(viewOf(v, d), { 0, 0, 0 }, { 1, 1, 1 }, ok, pyramid);
  EXPECT_NE(s.message.find("non-finite"), std::string::npos) << s.message;
}

// ---------------------------------------------------------------------------------------
// Surface ambient occlusion

TEST(SurfaceAO, SphereInAirIsOpenAndDarkerInsideABox)
{
  const vao::Index3 d = { 48, 48, 48 };
  const Vec3 c = { 23.5, 23.5, 23.5 };
  const double r = 6.0;
  auto sphere = [&](double x, double y, double z) {
    return std::sqrt((x - c[0]) * (x - c[0]) + (y - c[1]) * (y - c[1]) + (z - c[2]) * (z - c[2])) - r;
  };
  auto box = [&](double x, double y, double z) { // hollow shell, inner half-width 13, 3 thick
    const double m = std::max(std::fabs(x - c[0]), std::max(std::fabs(y - c[1]), std::fabs(z - c[2])));
    return std::max(13.0 - m, m - 16.0);
  };
  const Field air = makeField(d, sphere);
  const Field boxed = makeField(d, [&](double x, double y, double z) {
    return std::min(sphere(x, y, z), box(x, y, z));
  });
  std::vector<double> points, normals;
  spherePoints(c, r, 200, points, normals);
  const auto open = ao(air, pyramidOf(air), points, normals);
  const auto closed = ao(boxed, pyramidOf(boxed), points, normals);
  for (std::size_t i = 0; i < open.size(); ++i)
  {
    EXPECT_GT(open[i], 0.8f) << "point " << i;
    EXPECT_LE(open[i], 1.0f);
    EXPECT_GE(closed[i], 0.0f);
  }
  EXPECT_LT(average(closed), average(open) - 0.05);

  // The other options run and stay in [0, 1]; the mean of the levels is never darker
  // than their maximum.
  vao::SurfaceOcclusionParameters p;
  p.combination = vao::LevelCombination::Mean;
  const auto meanCombined = ao(boxed, pyramidOf(boxed), points, normals, p);
  for (std::size_t i = 0; i < open.size(); ++i)
    EXPECT_GE(meanCombined[i], closed[i] - 1e-6f);
  p = {};
  p.estimator = vao::Method::GaussianCdf;
  p.query = vao::SurfaceQuery::IsoValue;
  p.isoValue = 0.5;
  for (float x : ao(boxed, pyramidOf(boxed), points, normals, p))
  {
    EXPECT_GE(x, 0.0f);
    EXPECT_LE(x, 1.0f);
  }
}

TEST(SurfaceAO, DecreasesTowardsAWall)
{
  const vao::Index3 d = { 64, 24, 40 };
  // Floor z < 10, wall x < 8.
  const Field f = makeField(d, [](double x, double, double z) { return std::min(z - 10.0, x - 8.0); });
  const auto pyramid = pyramidOf(f);
  std::vector<double> points, normals;
  const double xs[] = { 50, 40, 32, 26, 21, 17, 14, 12, 10.5 };
  for (double x : xs)
  {
    points.insert(points.end(), { x, 11.5, 10.0 });
    normals.insert(normals.end(), { 0.0, 0.0, 2.0 }); // not unit: normalised inside
  }
  const auto values = ao(f, pyramid, points, normals);
  for (std::size_t i = 1; i < values.size(); ++i)
    EXPECT_LE(values[i], values[i - 1] + 1e-6f) << "x = " << xs[i];
  EXPECT_LT(values.back(), values.front() - 0.1f);
}

TEST(SurfaceAO, ChebyshevIsExactOnTwoValuedData)
{
  // A level whose every voxel holds the statistics of a mix of a (fraction 1 - f) and b
  // (fraction f), queried at b: the occluder fraction P(v >= b) is exactly f.
  const double a = -2.0, b = 5.0;
  for (double f : { 0.1, 0.25, 0.5, 0.8 })
  {
    vao::MomentLevel level;
    level.dims = { 3, 3, 3 };
    level.kernelRadius = 2.0;
    const double mean = f * b + (1 - f) * a;
    const double variance = f * (1 - f) * (b - a) * (b - a);
    level.mean.assign(27, static_cast<float>(mean));
    level.variance.assign(27, static_cast<float>(variance));
    const std::vector<vao::MomentLevel> pyramid = { level };
    vao::SurfaceOcclusionParameters p;
    p.query = vao::SurfaceQuery::IsoValue;
    p.isoValue = b;
    const double point[3] = { 0.7, 1.1, 0.4 }, normal[3] = { 0, 1, 0 };
    float out = -1;
    const vao::Status s = vao::surfaceAmbientOcclusion(
      pyramid, {}, { 0, 0, 0 }, { 1, 1, 1 }, point, normal, 1, p, &out);
    ASSERT_TRUE(s.ok) << s.message;
    EXPECT_NEAR(out, 1.0 - f, 1e-6) << "f = " << f;
  }
}

TEST(SurfaceAO, BadInputFailsWithMessage)
{
  const Field f = makeField({ 16, 16, 16 }, [](double, double, double z) { return z - 8.0; });
  const auto pyramid = pyramidOf(f, 2);
  float out = 0;
  auto expectFail = [&](const std::vector<vao::MomentLevel>& pyr, const double* point,
                      const double* normal, const vao::SurfaceOcclusionParameters& p) {
    const vao::Status s = vao::surfaceAmbientOcclusion(
      pyr, f.view(), f.origin, f.spacing, point, normal, 1, p, &out);
    EXPECT_FALSE(s.ok);
    EXPECT_FALSE(s.message.empty());
  };
  const double point[3] = { 8, 8, 8 }, up[3] = { 0, 0, 1 }, zero[3] = { 0, 0, 0 };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double badPoint[3] = { 8, nan, 8 }, badNormal[3] = { 0, nan, 1 };
  const vao::SurfaceOcclusionParameters ok;
  expectFail(pyramid, point, zero, ok);
  expectFail(pyramid, point, badNormal, ok);
  expectFail(pyramid, badPoint, up, ok);
  expectFail({}, point, up, ok);
  vao::SurfaceOcclusionParameters p = ok;
  p.offsetFactor = -1;
  expectFail(pyramid, point, up, p);
  p.offsetFactor = std::numeric_limits<double>::infinity();
  expectFail(pyramid, point, up, p);
  p = ok;
  p.levels = 3;
  expectFail(pyramid, point, up, p);
  p.levels = 0;
  expectFail(pyramid, point, up, p);
  // And the valid call succeeds.
  EXPECT_TRUE(vao::surfaceAmbientOcclusion(
    pyramid, f.view(), f.origin, f.spacing, point, up, 1, ok, &out).ok);
}

// ---------------------------------------------------------------------------------------
// Shadows

TEST(Shadow, SlabDarkensTheFarSideAndSwapsWithTheLight)
{
  const vao::Index3 d = { 32, 32, 48 };
  // Opaque slab 20 <= z <= 26.
  const Field f = makeField(d, [](double, double, double z) { return std::max(20.0 - z, z - 26.0); });
  const auto pyramid = pyramidOf(f);
  // Below the slab (z = 8) and above it (z = 38): small spheres' worth of upward facing points.
  std::vector<double> below, above, normals;
  for (double x : { 10.0, 16.0, 22.0 })
    for (double y : { 10.0, 16.0, 22.0 })
    {
      below.insert(below.end(), { x, y, 8.0 });
      above.insert(above.end(), { x, y, 38.0 });
      normals.insert(normals.end(), { 0.3, 0.0, 1.0 });
    }
  vao::SurfaceOcclusionParameters p;
  p.query = vao::SurfaceQuery::IsoValue;
  p.isoValue = 0.5;
  const std::int64_t n = static_cast<std::int64_t>(below.size() / 3);
  auto shadow = [&](const std::vector<double>& points, const Vec3& light) {
    std::vector<float> out(n, -1.0f);
    const vao::Status s =
      vao::surfaceShadow(pyramid, points.data(), normals.data(), n, light, p, out.data());
    EXPECT_TRUE(s.ok) << s.message;
    return out;
  };
  const auto belowUp = shadow(below, { 0, 0, 1 });
  const auto aboveUp = shadow(above, { 0, 0, 1 });
  const auto belowDown = shadow(below, { 0, 0, -3 });
  const auto aboveDown = shadow(above, { 0, 0, -3 });
  for (std::int64_t i = 0; i < n; ++i)
  {
    EXPECT_LT(belowUp[i], aboveUp[i] - 0.5f);
    EXPECT_LT(aboveDown[i], belowDown[i] - 0.5f);
    EXPECT_LT(belowUp[i], 0.05f);
    EXPECT_GT(aboveUp[i], 0.9f);
  }
  // The half-voxel-inside query (from level 0 here) runs too.
  p.query = vao::SurfaceQuery::HalfVoxelInside;
  for (float x : shadow(above, { 0, 0, 1 }))
  {
    EXPECT_GE(x, 0.0f);
    EXPECT_LE(x, 1.0f);
  }
}

TEST(Shadow, ZeroLightDirectionFailsWithMessage)
{
  const Field f = makeField({ 12, 12, 12 }, [](double, double, double z) { return z - 6.0; });
  const auto pyramid = pyramidOf(f, 2);
  const double point[3] = { 6, 6, 6 }, up[3] = { 0, 0, 1 };
  float out = 0;
  vao::Status s = vao::surfaceShadow(pyramid, point, up, 1, { 0, 0, 0 }, {}, &out);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("light"), std::string::npos) << s.message;
  s = vao::surfaceShadow(pyramid, point, up, 1, { 0, std::nan(""), 1 }, {}, &out);
  EXPECT_FALSE(s.ok);
  EXPECT_FALSE(s.message.empty());
  const double zero[3] = { 0, 0, 0 };
  s = vao::surfaceShadow(pyramid, point, zero, 1, { 0, 0, 1 }, {}, &out);
  EXPECT_FALSE(s.ok);
  EXPECT_FALSE(s.message.empty());
}
