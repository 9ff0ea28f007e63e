// The moment pyramid of variance occlusion maps (Penner & Mitchell 2008) against a
// brute-force blur and decimation, its precision, its sampling and its validation.
#include "PyramidTestSupport.h"

using namespace vaotest;

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
  EXPECT_NEAR(vao::sampleVolume(viewOf(v, d), origin, spacing, { -0.25, 3.0, 4.5 }), 1.5 + 15 + 250,
    1e-9); // index (1.5, 1.5, 2.5)
  EXPECT_NEAR(vao::sampleVolume(viewOf(v, d), origin, spacing, { 100.0, -5.0, 0.0 }), 3.0, 1e-9);
}

TEST(PyramidValidation, BadInputFailsWithMessage)
{
  const vao::Index3 d = { 6, 6, 6 };
  std::vector<float> v(216, 1.0f);
  std::vector<vao::MomentLevel> pyramid;
  const vao::PyramidParameters ok;
  auto expectFail =
    [&](const vao::VolumeView& view, const Vec3& spacing, const vao::PyramidParameters& p)
  {
    const vao::Status s = vao::buildMomentPyramid(view, { 0, 0, 0 }, spacing, p, pyramid);
    EXPECT_FALSE(s.ok);
    EXPECT_FALSE(s.message.empty());
  };
  expectFail(viewOf(v, { 6, 36, 1 }), { 1, 1, 1 }, ok);                            // 2-D
  expectFail(viewOf(v, d), { 1, 0, 1 }, ok);                                       // zero spacing
  expectFail(viewOf(v, d), { 1, std::numeric_limits<double>::infinity(), 1 }, ok); // inf spacing
  vao::PyramidParameters p = ok;
  p.levels = 0;
  expectFail(viewOf(v, d), { 1, 1, 1 }, p);
  p.levels = 17;
  expectFail(viewOf(v, d), { 1, 1, 1 }, p);
  v[100] = std::numeric_limits<float>::quiet_NaN();
  expectFail(viewOf(v, d), { 1, 1, 1 }, ok);
  const vao::Status s =
    vao::buildMomentPyramid(viewOf(v, d), { 0, 0, 0 }, { 1, 1, 1 }, ok, pyramid);
  EXPECT_NE(s.message.find("non-finite"), std::string::npos) << s.message;
}
