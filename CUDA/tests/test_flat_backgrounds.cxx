// Flat regions of data whose box sums are taken in double (float32, float64, the 32- and
// 64-bit integers): every voxel whose box holds one value only must get the exact
// openness, whatever the magnitude of the rest of the data. The rounding of the running
// double sums grows with the largest |v - shift| of the data, so a box of zeros next to
// values of 1e12 shows a spurious variance; the estimators must see through it.
//
// The reference is written here from docs/methods.md: the openness of a box is the fraction of
// its (clipped) voxels with v <= q; for a box of one value b and q = b that is 1.
#include "TestVolumes.h"
#include "vao/AmbientOcclusion.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <iostream>
#include <random>
#include <string>
#include <vector>

namespace
{

using vaotest::viewOf;

constexpr std::int64_t kSide = 28;

/// A ball of values around `background + magnitude` (relative noise 10%) in a constant
/// background, plus a few isolated voxels, so that flat and non-flat boxes meet.
template <class T>
std::vector<T> ballInBackground(double background, double magnitude, unsigned seed)
{
  std::mt19937_64 rng(seed);
  std::uniform_real_distribution<double> noise(-0.1, 0.1);
  std::vector<T> v(static_cast<std::size_t>(kSide * kSide * kSide), static_cast<T>(background));
  for (std::int64_t z = 0; z < kSide; ++z)
    for (std::int64_t y = 0; y < kSide; ++y)
      for (std::int64_t x = 0; x < kSide; ++x)
      {
        const double r2 = (x - 9.0) * (x - 9.0) + (y - 12.0) * (y - 12.0) + (z - 10.0) * (z - 10.0);
        const bool speck = (x * 7 + y * 13 + z * 29) % 997 == 0;
        if (r2 < 36.0 || speck)
          v[(z * kSide + y) * kSide + x] =
            static_cast<T>(background + magnitude * (1.0 + noise(rng)));
      }
  return v;
}

/// The exact openness of voxel (x, y, z) with q = its value, and whether its box is flat.
template <class T>
double exactOpenness(
  const std::vector<T>& v, std::int64_t x, std::int64_t y, std::int64_t z, int r, bool& flat)
{
  const T q = v[(z * kSide + y) * kSide + x];
  std::int64_t below = 0, total = 0;
  flat = true;
  for (std::int64_t k = std::max<std::int64_t>(0, z - r); k <= std::min(kSide - 1, z + r); ++k)
    for (std::int64_t j = std::max<std::int64_t>(0, y - r); j <= std::min(kSide - 1, y + r); ++j)
      for (std::int64_t i = std::max<std::int64_t>(0, x - r); i <= std::min(kSide - 1, x + r); ++i)
      {
        const T w = v[(k * kSide + j) * kSide + i];
        below += w <= q;
        flat = flat && w == q;
        ++total;
      }
  return static_cast<double>(below) / static_cast<double>(total);
}

/// Every method on every flat box of the volume: openness exactly the reference's.
template <class T>
void expectFlatBoxesExact(const std::vector<T>& v, const std::string& label)
{
  const vao::Index3 dims = { kSide, kSide, kSide };
  const vao::VolumeView view = viewOf(v, dims);
  for (int r : { 1, 3, 5 })
  {
    std::vector<double> exact(v.size());
    std::vector<char> flat(v.size());
    std::int64_t flats = 0;
    for (std::int64_t z = 0; z < kSide; ++z)
      for (std::int64_t y = 0; y < kSide; ++y)
        for (std::int64_t x = 0; x < kSide; ++x)
        {
          bool isFlat = false;
          const std::int64_t i = (z * kSide + y) * kSide + x;
          exact[i] = exactOpenness(v, x, y, z, r, isFlat);
          flat[i] = isFlat;
          flats += isFlat;
        }
    ASSERT_GT(flats, 1000) << label << ": the scene must have flat boxes";
    for (const vaotest::MethodCase& m : vaotest::kMomentMethodsAndExactBox)
    {
      vao::AmbientOcclusionParameters p;
      p.method = m.method;
      p.erfMode = m.erf;
      p.radius = { r, r, r };
      std::vector<float> open(v.size());
      ASSERT_TRUE(
        vao::computeAmbientOcclusion(view, vao::Region::whole(view), p, { open.data(), nullptr })
          .ok);
      std::int64_t wrong = 0, first = -1;
      for (std::size_t i = 0; i < v.size(); ++i)
        if (flat[i] && open[i] != static_cast<float>(exact[i]))
        {
          first = wrong == 0 ? static_cast<std::int64_t>(i) : first;
          ++wrong;
        }
      EXPECT_EQ(wrong, 0) << label << ", R = " << r << ", " << m.name << ": " << wrong << " of "
                          << flats << " flat boxes wrong, the first at index " << first << " (got "
                          << (first >= 0 ? open[first] : 0.0f) << ")";
    }
    // The Variance output: exactly 0 on every flat box (double sums leave rounding there,
    // which the flat rule reads as flat), and the box's own elsewhere.
    vao::AmbientOcclusionParameters p;
    p.radius = { r, r, r };
    std::vector<float> variance(v.size(), -1.0f);
    ASSERT_TRUE(
      vao::computeAmbientOcclusion(view, vao::Region::whole(view), p, { nullptr, variance.data() })
        .ok);
    std::int64_t nonzero = 0, zero = 0;
    for (std::size_t i = 0; i < v.size(); ++i)
    {
      nonzero += flat[i] && variance[i] != 0.0f;
      zero += !flat[i] && !(variance[i] > 0.0f);
    }
    EXPECT_EQ(nonzero, 0) << label << ", R = " << r << ": flat boxes with a variance";
    EXPECT_EQ(zero, 0) << label << ", R = " << r << ": boxes of two values without one";
  }
}

template <class T>
void expectEveryBackground(const char* type)
{
  for (double magnitude : { 1.0, 1e3, 1e6, 1e12 })
  {
    // 64-bit integers hold the magnitudes exactly; float32 rounds them, as users' data do.
    for (double background : { 0.0, 0.37 * magnitude + 3.0 })
    {
      const std::vector<T> v = ballInBackground<T>(background, magnitude, 11);
      expectFlatBoxesExact(v,
        std::string(type) + " background " + std::to_string(background) + " magnitude " +
          std::to_string(magnitude));
    }
  }
}

TEST(FlatBackgrounds, Float32EveryMethodEqualsExactBox)
{
  expectEveryBackground<float>("float32");
}

TEST(FlatBackgrounds, Float64EveryMethodEqualsExactBox)
{
  expectEveryBackground<double>("float64");
}

TEST(FlatBackgrounds, Int64EveryMethodEqualsExactBox)
{
  expectEveryBackground<std::int64_t>("int64");
}

TEST(FlatBackgrounds, UInt64EveryMethodEqualsExactBox)
{
  expectEveryBackground<std::uint64_t>("uint64");
}

TEST(FlatBackgrounds, TheReportedFloatCaseHasNoWrongVoxel)
{
  // A float32 object (40 +- 5) in a zero background, 40^3, radius 3, Gaussian CDF: the
  // background voxels whose box is all zeros are open (the exact answer is 1).
  const vao::Index3 dims = { 40, 40, 40 };
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> noise(-5.0f, 5.0f);
  std::vector<float> v(40 * 40 * 40, 0.0f);
  for (std::int64_t z = 10; z < 30; ++z)
    for (std::int64_t y = 10; y < 30; ++y)
      for (std::int64_t x = 10; x < 30; ++x)
        v[(z * 40 + y) * 40 + x] = 40.0f + noise(rng);
  vao::AmbientOcclusionParameters p;
  p.radius = { 3, 3, 3 };
  std::vector<float> open(v.size());
  ASSERT_TRUE(vao::computeAmbientOcclusion(
    viewOf(v, dims), vao::Region::whole(viewOf(v, dims)), p, { open.data(), nullptr })
                .ok);
  std::int64_t flats = 0, wrong = 0;
  for (std::int64_t z = 0; z < 40; ++z)
    for (std::int64_t y = 0; y < 40; ++y)
      for (std::int64_t x = 0; x < 40; ++x)
      {
        // The box reaches no object voxel: every coordinate is 4+ voxels outside [10, 30).
        const bool flat = x < 7 || x > 32 || y < 7 || y > 32 || z < 7 || z > 32;
        flats += flat;
        wrong += flat && open[(z * 40 + y) * 40 + x] != 1.0f;
      }
  EXPECT_EQ(flats, 40 * 40 * 40 - 26 * 26 * 26);
  EXPECT_EQ(wrong, 0);
}

TEST(FlatBackgrounds, SpuriousVarianceStaysWellUnderTheRoundingBound)
{
  // The margin of kSumRoundingUlps: the largest variance the box statistics show on a flat
  // box, in ulps of (largest |v - mean of the data|)^2, over the scenes above.
  double worst = 0.0;
  for (double magnitude : { 1.0, 1e3, 1e6, 1e12 })
    for (double background : { 0.0, 0.37 * magnitude + 3.0 })
    {
      const std::vector<double> v = ballInBackground<double>(background, magnitude, 11);
      const vao::Index3 dims = { kSide, kSide, kSide };
      const vao::VolumeView view = viewOf(v, dims);
      double mean = 0.0;
      for (double w : v)
        mean += w / static_cast<double>(v.size());
      double deviation = 0.0;
      for (double w : v)
        deviation = std::max(deviation, std::abs(w - mean));
      for (int r : { 1, 3, 5 })
      {
        std::vector<double> variance(v.size());
        vao::BoxStatisticsOutput out;
        out.variance = variance.data();
        ASSERT_TRUE(vao::computeBoxStatistics(view, vao::Region::whole(view), { r, r, r }, out).ok);
        for (std::int64_t z = 0; z < kSide; ++z)
          for (std::int64_t y = 0; y < kSide; ++y)
            for (std::int64_t x = 0; x < kSide; ++x)
            {
              bool flat = false;
              exactOpenness(v, x, y, z, r, flat);
              if (flat)
                worst = std::max(worst,
                  variance[(z * kSide + y) * kSide + x] /
                    (2.220446049250313e-16 * deviation * deviation));
            }
      }
    }
  std::cout << "[ rounding ] largest spurious variance on a flat box: " << worst
            << " ulps of deviation^2\n";
  EXPECT_LT(worst * 4.0, vao::kSumRoundingUlps) << "the rounding bound has too little margin";
}

} // namespace
