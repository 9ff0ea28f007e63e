// Surface ambient occlusion and soft shadows sampled from the moment pyramid (Penner &
// Mitchell 2008): behaviour on known scenes, exactness of Chebyshev on two-valued data,
// and the validation of the arguments.
#include "PyramidTestSupport.h"

using namespace vaotest;

// ---------------------------------------------------------------------------------------
// Surface ambient occlusion

TEST(SurfaceAO, SphereInAirIsOpenAndDarkerInsideABox)
{
  const vao::Index3 d = { 48, 48, 48 };
  const Vec3 c = { 23.5, 23.5, 23.5 };
  const double r = 6.0;
  auto sphere = [&](double x, double y, double z)
  {
    return std::sqrt((x - c[0]) * (x - c[0]) + (y - c[1]) * (y - c[1]) + (z - c[2]) * (z - c[2])) -
      r;
  };
  auto box = [&](double x, double y, double z) { // hollow shell, inner half-width 13, 3 thick
    const double m =
      std::max(std::fabs(x - c[0]), std::max(std::fabs(y - c[1]), std::fabs(z - c[2])));
    return std::max(13.0 - m, m - 16.0);
  };
  const Field air = makeField(d, sphere);
  const Field boxed = makeField(
    d, [&](double x, double y, double z) { return std::min(sphere(x, y, z), box(x, y, z)); });
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
  const Field f =
    makeField(d, [](double x, double, double z) { return std::min(z - 10.0, x - 8.0); });
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

TEST(SurfaceAO, FlatRegionsOfLargeMagnitudeDataAreOpen)
{
  // Zeros with a block of large values in one corner: far from the block every level is
  // flat at 0, and a surface there queried at 0 is fully open (Penner & Mitchell's flat
  // case). The blurred moments round with the data's magnitude; the flat rule must see
  // through that at every magnitude and for both estimators.
  const vao::Index3 dims = { 40, 40, 40 };
  for (double magnitude : { 1.0, 1e3, 1e6, 1e12 })
    for (int type = 0; type < 2; ++type)
    {
      std::vector<float> f(40 * 40 * 40, 0.0f);
      std::vector<double> d(f.size(), 0.0);
      for (std::int64_t z = 0; z < 8; ++z)
        for (std::int64_t y = 0; y < 8; ++y)
          for (std::int64_t x = 0; x < 8; ++x)
          {
            f[(z * 40 + y) * 40 + x] = static_cast<float>(magnitude * (1.0 + 0.01 * x));
            d[(z * 40 + y) * 40 + x] = magnitude * (1.0 + 0.01 * x);
          }
      const vao::VolumeView view = type == 0 ? viewOf(f, dims) : viewOf(d, dims);
      std::vector<vao::MomentLevel> pyramid;
      vao::PyramidParameters pp;
      pp.levels = 3;
      ASSERT_TRUE(vao::buildMomentPyramid(view, { 0, 0, 0 }, { 1, 1, 1 }, pp, pyramid).ok);
      for (vao::Method estimator : { vao::Method::Chebyshev, vao::Method::GaussianCdf })
      {
        vao::SurfaceOcclusionParameters p;
        p.query = vao::SurfaceQuery::IsoValue;
        p.isoValue = 0.0;
        p.estimator = estimator;
        // Three levels reach 2 + 4 + 8 = 14 voxels (offsets up to 8): the points stay 16+ away.
        const double points[6] = { 33.0, 32.0, 31.0, 36.5, 30.0, 35.0 };
        const double normals[6] = { 0, 0, 1, 1, 0, 0 };
        float out[2] = { -1, -1 };
        ASSERT_TRUE(vao::surfaceAmbientOcclusion(
          pyramid, view, { 0, 0, 0 }, { 1, 1, 1 }, points, normals, 2, p, out)
                      .ok);
        EXPECT_EQ(out[0], 1.0f) << "magnitude " << magnitude << (type ? " float64" : " float32");
        EXPECT_EQ(out[1], 1.0f) << "magnitude " << magnitude << (type ? " float64" : " float32");
      }
    }
}

TEST(SurfaceAO, BadInputFailsWithMessage)
{
  const Field f = makeField({ 16, 16, 16 }, [](double, double, double z) { return z - 8.0; });
  const auto pyramid = pyramidOf(f, 2);
  float out = 0;
  auto expectFail = [&](const std::vector<vao::MomentLevel>& pyr, const double* point,
                      const double* normal, const vao::SurfaceOcclusionParameters& p)
  {
    const vao::Status s =
      vao::surfaceAmbientOcclusion(pyr, f.view(), f.origin, f.spacing, point, normal, 1, p, &out);
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
  EXPECT_TRUE(
    vao::surfaceAmbientOcclusion(pyramid, f.view(), f.origin, f.spacing, point, up, 1, ok, &out)
      .ok);
}

// ---------------------------------------------------------------------------------------
// Shadows

TEST(Shadow, SlabDarkensTheFarSideAndSwapsWithTheLight)
{
  const vao::Index3 d = { 32, 32, 48 };
  // Opaque slab 20 <= z <= 26.
  const Field f =
    makeField(d, [](double, double, double z) { return std::max(20.0 - z, z - 26.0); });
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
  auto shadow = [&](const std::vector<double>& points, const Vec3& light)
  {
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

// ---------------------------------------------------------------------------------------
// Float points and normals

TEST(SurfacePoints, FloatPointsGiveTheBitsOfTheirDoubles)
{
  // A sphere inside a box shell, its points rounded to float (as vtkPoints holds them) and
  // off the grid; the double calls get the same values widened, so every output must match
  // bit for bit, AO and shadows, with both queries and the estimators of both levels' paths.
  const vao::Index3 d = { 40, 36, 44 };
  const Vec3 c = { 19.3, 17.6, 21.1 };
  const Field f = sphereInShell(d, c);
  const auto pyramid = pyramidOf(f);
  std::vector<double> points, normals;
  spherePoints(c, 5.5, 333, points, normals); // 333: the last batch of lanes is partial
  for (std::size_t i = 0; i < normals.size(); ++i)
    normals[i] *= 0.5 + (i % 5); // not unit
  std::vector<float> pointsF(points.begin(), points.end()),
    normalsF(normals.begin(), normals.end());
  const std::vector<double> widenedPoints(pointsF.begin(), pointsF.end());
  const std::vector<double> widenedNormals(normalsF.begin(), normalsF.end());
  const std::int64_t n = static_cast<std::int64_t>(points.size() / 3);
  forEachSurfaceQuery(
    [&](const vao::SurfaceOcclusionParameters& p)
    {
      std::vector<float> fromFloat(n, -1.0f), fromDouble(n, -2.0f), shadowFloat(n, -1.0f),
        shadowDouble(n, -2.0f);
      ASSERT_TRUE(vao::surfaceAmbientOcclusion(pyramid, f.view(), f.origin, f.spacing,
        pointsF.data(), normalsF.data(), n, p, fromFloat.data())
                    .ok);
      ASSERT_TRUE(vao::surfaceAmbientOcclusion(pyramid, f.view(), f.origin, f.spacing,
        widenedPoints.data(), widenedNormals.data(), n, p, fromDouble.data())
                    .ok);
      ASSERT_TRUE(vao::surfaceShadow(
        pyramid, pointsF.data(), normalsF.data(), n, { 0.2, -0.5, 1 }, p, shadowFloat.data())
                    .ok);
      ASSERT_TRUE(vao::surfaceShadow(pyramid, widenedPoints.data(), widenedNormals.data(), n,
        { 0.2, -0.5, 1 }, p, shadowDouble.data())
                    .ok);
      for (std::int64_t i = 0; i < n; ++i)
      {
        ASSERT_EQ(fromFloat[i], fromDouble[i]) << "AO, point " << i;
        ASSERT_EQ(shadowFloat[i], shadowDouble[i]) << "shadow, point " << i;
      }
      EXPECT_GT(average(fromFloat), 0.05); // open and shadowed points both
      EXPECT_LT(average(fromFloat), 0.95);
      const auto range =
        std::minmax_element(shadowFloat.begin(), shadowFloat.end()); // inside the shell
      EXPECT_GT(*range.second - *range.first, 0.05f);
    });
  // Bad float input is named as with doubles.
  const float bad[3] = { 8, std::numeric_limits<float>::quiet_NaN(), 8 }, up[3] = { 0, 0, 1 },
              zero[3] = { 0, 0, 0 };
  const float tiny[3] = { 0, 0, 1e-30f }; // its square is 0 in float, not in double
  float out = 0;
  vao::Status s =
    vao::surfaceAmbientOcclusion(pyramid, f.view(), f.origin, f.spacing, bad, up, 1, {}, &out);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("point 0"), std::string::npos) << s.message;
  s = vao::surfaceShadow(pyramid, up, zero, 1, { 0, 0, 1 }, {}, &out);
  EXPECT_NE(s.message.find("zero normal"), std::string::npos) << s.message;
  EXPECT_TRUE(vao::surfaceShadow(pyramid, up, tiny, 1, { 0, 0, 1 }, {}, &out).ok);
}
