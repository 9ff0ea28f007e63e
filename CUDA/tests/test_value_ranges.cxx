// The ranges of an output array (vao/ValueRanges.h) against a plain scan, and the cases
// it leaves to VTK (no tuple, a NaN, an infinity).
#include "vao/ValueRanges.h"

#include "cpu/common/ConcurrentRange.h"
#include "cpu/simd/CpuDispatch.h"
#include "vao/AmbientOcclusion.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace
{

TEST(ValueRanges, EqualAPlainScanPerComponentAndOfTheNorm)
{
  std::mt19937 random(5);
  for (int components : { 1, 3, 8 })
  {
    for (std::int64_t tuples : { 1, 7, 1000, 100003 })
    {
      std::vector<float> values(static_cast<std::size_t>(tuples * components));
      for (std::size_t i = 0; i < values.size(); ++i)
      {
        const int c = static_cast<int>(i % components);
        // Component c spans a range of its own: a wrong component index shows.
        values[i] =
          std::uniform_real_distribution<float>(-10.0f * c - 1.0f, 100.0f * c + 0.5f)(random);
      }
      for (int threads : { 1, 2, 3 })
      {
        SCOPED_TRACE(::testing::Message()
          << components << " components, " << tuples << " tuples, " << threads << " threads");
        vao::ValueRanges ranges;
        ASSERT_TRUE(
          vao::computeFiniteValueRanges(values.data(), tuples, components, ranges, threads));
        ASSERT_EQ(ranges.components.size(), static_cast<std::size_t>(2 * components));
        double lowestSquare = std::numeric_limits<double>::max(), highestSquare = 0.0;
        for (std::int64_t t = 0; t < tuples; ++t)
        {
          double square = 0.0;
          for (int c = 0; c < components; ++c)
          {
            const double v = values[static_cast<std::size_t>(t * components + c)];
            square += v * v;
          }
          lowestSquare = std::min(lowestSquare, square);
          highestSquare = std::max(highestSquare, square);
        }
        for (int c = 0; c < components; ++c)
        {
          float lo = values[c], hi = values[c];
          for (std::int64_t t = 1; t < tuples; ++t)
          {
            lo = std::min(lo, values[static_cast<std::size_t>(t * components + c)]);
            hi = std::max(hi, values[static_cast<std::size_t>(t * components + c)]);
          }
          EXPECT_EQ(ranges.components[2 * c], lo) << "component " << c;
          EXPECT_EQ(ranges.components[2 * c + 1], hi) << "component " << c;
        }
        if (components > 1)
        {
          EXPECT_EQ(ranges.norm[0], std::sqrt(lowestSquare));
          EXPECT_EQ(ranges.norm[1], std::sqrt(highestSquare));
        }
        else
        {
          EXPECT_TRUE(std::isnan(ranges.norm[0]) && std::isnan(ranges.norm[1]));
        }
      }
    }
  }
}

TEST(ValueRanges, LeaveNoTuplesNaNAndInfinityToTheCaller)
{
  vao::ValueRanges ranges;
  std::vector<float> values(3000, 1.0f);
  EXPECT_FALSE(vao::computeFiniteValueRanges(values.data(), 0, 3, ranges));
  EXPECT_FALSE(vao::computeFiniteValueRanges(nullptr, 10, 3, ranges));
  for (float bad : { std::numeric_limits<float>::quiet_NaN(),
         std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity() })
  {
    for (std::size_t at : { std::size_t(0), std::size_t(1501), values.size() - 1 })
    {
      std::vector<float> spoiled = values;
      spoiled[at] = bad;
      EXPECT_FALSE(vao::computeFiniteValueRanges(spoiled.data(), 1000, 3, ranges, 2))
        << bad << " at " << at;
    }
  }
  // The largest finite floats square to finite doubles: still a range.
  values[4] = std::numeric_limits<float>::max();
  values[5] = -std::numeric_limits<float>::max();
  EXPECT_TRUE(vao::computeFiniteValueRanges(values.data(), 1000, 3, ranges, 2));
  EXPECT_EQ(ranges.components[3], static_cast<double>(std::numeric_limits<float>::max()));
}

} // namespace

// The range a pass keeps as it writes (ConcurrentRange.h): each row's extremes on every
// tier against a plain scan, with a NaN or an infinity anywhere making it unknown; and
// computeAmbientOcclusion's openness range, known for the moment methods and equal to a
// scan of what they wrote, unknown for the others.
namespace
{

TEST(KeptRanges, RowExtremesOnEveryTierEqualAPlainScan)
{
  using vao::detail::SimdTier;
  std::mt19937 random(12);
  for (const SimdTier tier : { SimdTier::Baseline, SimdTier::Avx2, SimdTier::Avx512 })
  {
    vao::detail::limitSimdTier(tier);
    for (std::int64_t n = 0; n <= 50; ++n)
    {
      std::vector<float> v(static_cast<std::size_t>(n));
      for (float& x : v)
        x = std::uniform_real_distribution<float>(-3.0f, 5.0f)(random);
      float lo = std::numeric_limits<float>::infinity(), hi = -lo;
      ASSERT_TRUE(vao::detail::rowExtremes(v.data(), n, lo, hi));
      if (n > 0)
      {
        EXPECT_EQ(lo, *std::min_element(v.begin(), v.end())) << "n " << n;
        EXPECT_EQ(hi, *std::max_element(v.begin(), v.end())) << "n " << n;
      }
      for (const float bad :
        { std::numeric_limits<float>::quiet_NaN(), std::numeric_limits<float>::infinity() })
        for (std::int64_t at = 0; at < n; at += 7)
        {
          std::vector<float> w = v;
          w[static_cast<std::size_t>(at)] = bad;
          float l = 0.0f, h = 0.0f;
          EXPECT_FALSE(vao::detail::rowExtremes(w.data(), n, l, h)) << "n " << n << ", at " << at;
        }
    }
  }
  vao::detail::limitSimdTier(SimdTier::Avx512);
}

TEST(KeptRanges, OpennessRangeOfTheMomentMethodsEqualsAScan)
{
  const vao::Index3 dims = { 23, 19, 17 };
  std::vector<std::int16_t> values(static_cast<std::size_t>(dims[0] * dims[1] * dims[2]));
  std::mt19937 random(3);
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] = static_cast<std::int16_t>(
      i % 11 == 0 ? 900 : std::uniform_int_distribution<int>(-50, 50)(random));
  std::vector<float> floats(values.begin(), values.end());
  for (const bool asFloat : { false, true })
  {
    vao::VolumeView view;
    view.data = asFloat ? static_cast<const void*>(floats.data()) : values.data();
    view.type = asFloat ? vao::ScalarType::Float32 : vao::ScalarType::Int16;
    view.dims = dims;
    for (const vao::Method method : { vao::Method::GaussianCdf, vao::Method::Chebyshev,
           vao::Method::CdfReconstruction, vao::Method::ExactBox })
    {
      vao::AmbientOcclusionParameters p;
      p.method = method;
      p.radius = { 2, 3, 1 };
      std::vector<float> out(values.size());
      vao::OutputRange range;
      range.known = true; // stale: the call must reset it
      vao::AmbientOcclusionOutput output;
      output.openness = out.data();
      output.opennessRange = &range;
      ASSERT_TRUE(vao::computeAmbientOcclusion(view, vao::Region::whole(view), p, output).ok);
      if (method == vao::Method::ExactBox)
      {
        EXPECT_FALSE(range.known);
        continue;
      }
      // Without vector instructions the range is left to the caller's threaded pass.
      vao::detail::limitSimdTier(vao::detail::SimdTier::Baseline);
      vao::OutputRange plainRange;
      plainRange.known = true;
      output.opennessRange = &plainRange;
      ASSERT_TRUE(vao::computeAmbientOcclusion(view, vao::Region::whole(view), p, output).ok);
      vao::detail::limitSimdTier(vao::detail::SimdTier::Avx512);
      EXPECT_FALSE(plainRange.known);
      output.opennessRange = &range;
      ASSERT_TRUE(vao::computeAmbientOcclusion(view, vao::Region::whole(view), p, output).ok);
      if (!vao::detail::cpuHasAvx2())
      {
        EXPECT_FALSE(range.known); // a processor without AVX2 leaves it to the caller's pass
        continue;
      }
      ASSERT_TRUE(range.known) << static_cast<int>(method);
      EXPECT_EQ(range.lowest, *std::min_element(out.begin(), out.end()))
        << static_cast<int>(method);
      EXPECT_EQ(range.highest, *std::max_element(out.begin(), out.end()))
        << static_cast<int>(method);
      EXPECT_LT(range.lowest, range.highest); // a scene with both open and occluded voxels
    }
  }
}

} // namespace
