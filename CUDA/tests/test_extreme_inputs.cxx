// Values and spacings at the edges of floating point: a correct result or a clear error,
// never garbage. The references are the same scenes at ordinary scales.
#include "SweepTestSupport.h"
#include "TestVolumes.h"
#include "vao/AmbientOcclusion.h"
#include "vao/Shading.h"
#include "vao/VarianceOcclusionMap.h"

#include <gtest/gtest.h>

#include <cfloat>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

namespace
{

using namespace vaotest;

vao::SweepParameters sweepWithOctants()
{
  vao::SweepParameters p = withIterations(2);
  p.isoValue = 0.0;
  return p;
}

/// D and A of the sweeps of `scene` values at spacing h (isotropic).
void sweepAt(const std::vector<double>& values, const vao::Index3& dims, double h,
  std::vector<float>& d, std::vector<float>& a, vao::Status& status)
{
  const std::size_t n = values.size();
  d.assign(n, 0.0f);
  a.assign(n, 0.0f);
  status = vao::computeOcclusionSweeping(
    viewOf(values, dims), { h, h, h }, sweepWithOctants(), { d.data(), a.data() });
}

std::vector<double> ballValues(const vao::Index3& dims, double inside, double outside)
{
  std::vector<double> v;
  for (std::int64_t z = 0; z < dims[2]; ++z)
    for (std::int64_t y = 0; y < dims[1]; ++y)
      for (std::int64_t x = 0; x < dims[0]; ++x)
      {
        const double r =
          std::sqrt((x - 9.3) * (x - 9.3) + (y - 8.1) * (y - 8.1) + (z - 10.4) * (z - 10.4));
        v.push_back(r < 5.5 ? inside : outside);
      }
  return v;
}

TEST(ExtremeInputs, SweepingDistancesScaleWithAnySpacingInItsRange)
{
  const vao::Index3 dims = { 19, 17, 21 };
  const std::vector<double> values = ballValues(dims, 1.0, -1.0);
  std::vector<float> d1, a1;
  vao::Status status;
  sweepAt(values, dims, 1.0, d1, a1, status);
  ASSERT_TRUE(status.ok) << status.message;
  for (double h : { 1e-10, 3e-7, 1e-30, 1e30, 0.75, 2.0 })
  {
    std::vector<float> d, a;
    sweepAt(values, dims, h, d, a, status);
    ASSERT_TRUE(status.ok) << "spacing " << h << ": " << status.message;
    double worst = 0.0, worstOcclusion = 0.0;
    for (std::size_t i = 0; i < d.size(); ++i)
    {
      ASSERT_TRUE(std::isfinite(d[i])) << "spacing " << h << ", voxel " << i;
      worst = std::max(worst, std::abs(d[i] / h - d1[i]));
      worstOcclusion = std::max(worstOcclusion, std::abs(static_cast<double>(a[i]) - a1[i]));
    }
    // D is float: a few ulps of the largest distance (~20 voxels) after the rescaling.
    EXPECT_LT(worst, 1e-4) << "spacing " << h << ": distances in voxels differ from spacing 1";
    EXPECT_LT(worstOcclusion, 1e-5) << "spacing " << h;
  }
}

TEST(ExtremeInputs, SweepingRejectsSpacingsOutsideItsRangeWithAReason)
{
  const vao::Index3 dims = { 8, 8, 8 };
  const std::vector<double> values = ballValues(dims, 1.0, -1.0);
  std::vector<float> d, a;
  vao::Status status;
  for (double h : { 1e-31, 1e31 })
  {
    sweepAt(values, dims, h, d, a, status);
    EXPECT_FALSE(status.ok) << "spacing " << h;
    EXPECT_NE(status.message.find("spacings between"), std::string::npos) << status.message;
  }
}

TEST(ExtremeInputs, SweepingFindsTheSurfaceBetweenTheLargestDoubles)
{
  // Inside +DBL_MAX, outside -DBL_MAX, iso 0: every crossing is half-way, as for +-1.
  const vao::Index3 dims = { 19, 17, 21 };
  std::vector<float> dHuge, aHuge, dUnit, aUnit;
  vao::Status status;
  sweepAt(ballValues(dims, DBL_MAX, -DBL_MAX), dims, 1.0, dHuge, aHuge, status);
  ASSERT_TRUE(status.ok) << status.message;
  sweepAt(ballValues(dims, 1.0, -1.0), dims, 1.0, dUnit, aUnit, status);
  ASSERT_TRUE(status.ok) << status.message;
  for (std::size_t i = 0; i < dHuge.size(); ++i)
  {
    ASSERT_EQ(dHuge[i], dUnit[i]) << "voxel " << i;
    ASSERT_EQ(aHuge[i], aUnit[i]) << "voxel " << i;
  }
}

TEST(ExtremeInputs, MomentMethodsRefuseValuesWhoseSquaresOverflow)
{
  const vao::Index3 dims = { 10, 10, 10 };
  std::vector<double> values = ballValues(dims, 1e200, 0.0);
  const vao::VolumeView view = viewOf(values, dims);
  std::vector<float> open(values.size());
  vao::AmbientOcclusionParameters p;
  p.radius = { 2, 2, 2 };
  for (vao::Method m :
    { vao::Method::GaussianCdf, vao::Method::Chebyshev, vao::Method::CdfReconstruction })
  {
    p.method = m;
    const vao::Status s =
      vao::computeAmbientOcclusion(view, vao::Region::whole(view), p, { open.data(), nullptr });
    EXPECT_FALSE(s.ok);
    EXPECT_NE(s.message.find("rescale"), std::string::npos) << s.message;
  }
  std::vector<vao::MomentLevel> pyramid;
  const vao::Status s = vao::buildMomentPyramid(view, { 0, 0, 0 }, { 1, 1, 1 }, {}, pyramid);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("rescale"), std::string::npos) << s.message;
  EXPECT_TRUE(pyramid.empty());

  // At the limit the estimators still see the scene as at unit scale.
  values = ballValues(dims, 1e140, 0.0);
  std::vector<double> unit = ballValues(dims, 1.0, 0.0);
  std::vector<float> openUnit(values.size());
  p.method = vao::Method::GaussianCdf;
  ASSERT_TRUE(vao::computeAmbientOcclusion(
    viewOf(values, dims), vao::Region::whole(view), p, { open.data(), nullptr })
                .ok);
  ASSERT_TRUE(vao::computeAmbientOcclusion(
    viewOf(unit, dims), vao::Region::whole(view), p, { openUnit.data(), nullptr })
                .ok);
  for (std::size_t i = 0; i < open.size(); ++i)
    ASSERT_NEAR(open[i], openUnit[i], 1e-6) << "voxel " << i;
}

/// The openness of every voxel of `values` (q = its own value) by `method`, R = 2.
template <class T>
std::vector<float> opennessOf(
  const std::vector<T>& values, const vao::Index3& dims, vao::Method method)
{
  vao::AmbientOcclusionParameters p;
  p.radius = { 2, 2, 2 };
  p.method = method;
  std::vector<float> open(values.size(), -1.0f);
  const vao::VolumeView view = viewOf(values, dims);
  const vao::Status s =
    vao::computeAmbientOcclusion(view, vao::Region::whole(view), p, { open.data(), nullptr });
  EXPECT_TRUE(s.ok) << s.message;
  return open;
}

template <class T, class F>
std::vector<T> mapped(const std::vector<std::int16_t>& values, F&& f)
{
  std::vector<T> out;
  for (const std::int16_t v : values)
    out.push_back(static_cast<T>(f(double(v))));
  return out;
}

// The moment estimators depend on (q - mu) / sigma alone: soft tissue of a CT (990 to 1010,
// flat blocks among it) stored with an offset of 1e8 or 1e12, or in units of 1e-10, 2^-40
// or 1e-30, is the same scene. Before the flat rule stopped being relative to max(1, mu^2),
// every box there was flat and the openness 0 or 1.
TEST(ExtremeInputs, MomentMethodsSeeTheSameSceneAtAnyOffsetAndScale)
{
  const vao::Index3 dims = { 14, 13, 12 };
  const std::vector<std::int16_t> base = randomVolume<std::int16_t>(dims, 990, 1010, 5);
  for (vao::Method method :
    { vao::Method::GaussianCdf, vao::Method::Chebyshev, vao::Method::CdfReconstruction })
  {
    SCOPED_TRACE(static_cast<int>(method));
    const std::vector<float> expected = opennessOf(base, dims, method);
    const std::vector<std::vector<float>> variants = {
      opennessOf(mapped<std::int32_t>(base, [](double v) { return v + 1e8; }), dims, method),
      opennessOf(mapped<std::int64_t>(base, [](double v) { return v - 1e12; }), dims, method),
      opennessOf(mapped<double>(base, [](double v) { return v * 1e-10; }), dims, method),
      opennessOf(mapped<double>(base, [](double v) { return v * 1e-30 + 5e-27; }), dims, method),
      opennessOf(mapped<float>(base, [](double v) { return std::ldexp(v, -40); }), dims, method),
    };
    for (std::size_t k = 0; k < variants.size(); ++k)
      for (std::size_t i = 0; i < expected.size(); ++i)
        ASSERT_NEAR(variants[k][i], expected[i], 1e-5) << "variant " << k << ", voxel " << i;
  }
}

// The pyramid's levels hold means and variances as float32: a ball of 1e-30 in 0 (its
// variances near 1e-61) built levels of zeros, every sample flat, and one of 1e20 levels of
// infinities; Isosurface Ambient Occlusion then gave AO 0 or 1 everywhere. Such spans are
// refused with a reason; inside the range the levels are the unit scene's, scaled.
TEST(ExtremeInputs, PyramidRefusesSpansItsFloatLevelsCannotHold)
{
  const vao::Index3 dims = { 10, 10, 10 };
  for (const double inside : { 1e-30, -3e-18, 1e20, -2e18 })
  {
    const std::vector<double> values = ballValues(dims, inside, 0.0);
    std::vector<vao::MomentLevel> pyramid;
    const vao::Status s =
      vao::buildMomentPyramid(viewOf(values, dims), { 0, 0, 0 }, { 1, 1, 1 }, {}, pyramid);
    EXPECT_FALSE(s.ok) << inside;
    EXPECT_NE(s.message.find("rescale"), std::string::npos) << s.message;
    EXPECT_TRUE(pyramid.empty());
  }
  // A constant volume has no variance to lose, whatever its value.
  std::vector<vao::MomentLevel> constant;
  EXPECT_TRUE(vao::buildMomentPyramid(
    viewOf(ballValues(dims, 1e-30, 1e-30), dims), { 0, 0, 0 }, { 1, 1, 1 }, {}, constant)
                .ok);

  const std::vector<double> unit = ballValues(dims, 1.0, 0.0);
  std::vector<vao::MomentLevel> expected;
  ASSERT_TRUE(
    vao::buildMomentPyramid(viewOf(unit, dims), { 0, 0, 0 }, { 1, 1, 1 }, {}, expected).ok);
  for (const int exponent : { -50, 55 })
  {
    const std::vector<double> scaled = ballValues(dims, std::ldexp(1.0, exponent), 0.0);
    std::vector<vao::MomentLevel> pyramid;
    const vao::Status s =
      vao::buildMomentPyramid(viewOf(scaled, dims), { 0, 0, 0 }, { 1, 1, 1 }, {}, pyramid);
    ASSERT_TRUE(s.ok) << s.message;
    ASSERT_EQ(pyramid.size(), expected.size());
    for (std::size_t l = 0; l < pyramid.size(); ++l)
      for (std::size_t i = 0; i < pyramid[l].mean.size(); ++i)
      {
        ASSERT_NEAR(std::ldexp(pyramid[l].mean[i], -exponent), expected[l].mean[i], 1e-6)
          << l << " " << i;
        ASSERT_NEAR(
          std::ldexp(pyramid[l].variance[i], -2 * exponent), expected[l].variance[i], 1e-6)
          << l << " " << i;
      }
  }
}

TEST(ExtremeInputs, ByteOfNanIsZeroNotUndefined)
{
  EXPECT_EQ(vao::toByte(std::numeric_limits<double>::quiet_NaN()), 0);
  EXPECT_EQ(vao::toByte(-std::numeric_limits<double>::infinity()), 0);
  EXPECT_EQ(vao::toByte(std::numeric_limits<double>::infinity()), 255);
  EXPECT_EQ(vao::toByte(0.5), 128);
}

} // namespace
