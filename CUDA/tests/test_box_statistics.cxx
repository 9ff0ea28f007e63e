// The separable box statistics against a brute-force reference.
#include "ResultComparison.h"
#include "TestVolumes.h"

#include <gtest/gtest.h>

using namespace vaotest;

namespace
{

/// Checks every voxel of `region` against brute force: min/max exact, the rest to 1e-9.
template <class T>
void expectStatsMatchBruteForce(const std::vector<T>& v, const vao::Index3& dims,
  const vao::Radius& r, const vao::Region& region, int threads)
{
  StatsArrays got(region.voxelCount());
  vao::Execution execution;
  execution.threads = threads;
  const vao::Status status =
    vao::computeBoxStatistics(viewOf(v, dims), region, r, got.output(), execution);
  ASSERT_TRUE(status.ok) << status.message;
  std::int64_t k = 0, failures = 0;
  for (std::int64_t z = region.begin[2]; z < region.begin[2] + region.size[2]; ++z)
    for (std::int64_t y = region.begin[1]; y < region.begin[1] + region.size[1]; ++y)
      for (std::int64_t x = region.begin[0]; x < region.begin[0] + region.size[0]; ++x, ++k)
      {
        const ReferenceStats ref = bruteForceStats(v, dims, r, x, y, z);
        const bool ok = got.count[k] == ref.count && got.minimum[k] == ref.minimum &&
          got.maximum[k] == ref.maximum && closeRelative(got.mean[k], ref.mean, 1e-9) &&
          closeRelative(got.variance[k], ref.variance, 1e-9);
        if (!ok && failures++ < 5)
        {
          ADD_FAILURE() << "voxel (" << x << "," << y << "," << z << ") radius (" << r.x << ","
                        << r.y << "," << r.z << "): count " << got.count[k] << " vs " << ref.count
                        << ", mean " << got.mean[k] << " vs " << ref.mean << ", variance "
                        << got.variance[k] << " vs " << ref.variance << ", min " << got.minimum[k]
                        << " vs " << ref.minimum << ", max " << got.maximum[k] << " vs "
                        << ref.maximum;
        }
      }
  EXPECT_EQ(failures, 0);
}

template <class T>
class BoxStatisticsTyped : public ::testing::Test
{
};

using ScalarTypes = ::testing::Types<std::int8_t, std::uint8_t, std::int16_t, std::uint16_t,
  std::int32_t, std::uint32_t, std::int64_t, std::uint64_t, float, double>;
TYPED_TEST_SUITE(BoxStatisticsTyped, ScalarTypes);

TYPED_TEST(BoxStatisticsTyped, IsotropicRadiiZeroToSixOnOddVolume)
{
  const vao::Index3 dims = { 17, 11, 9 };
  const double lo = std::is_signed<TypeParam>::value ? -100 : 0;
  const auto v = randomVolume<TypeParam>(dims, lo, lo + 120, 7);
  for (int r = 0; r <= 6; ++r)
  {
    SCOPED_TRACE(r);
    expectStatsMatchBruteForce(v, dims, { r, r, r }, vao::Region::whole(viewOf(v, dims)), 2);
  }
}

TYPED_TEST(BoxStatisticsTyped, AnisotropicRadiiAndRadiiLargerThanTheVolume)
{
  const vao::Index3 dims = { 13, 7, 10 };
  const auto v = randomVolume<TypeParam>(dims, 0, 90, 11);
  const vao::Radius radii[] = { { 1, 0, 2 }, { 3, 1, 0 }, { 0, 5, 1 }, { 20, 2, 4 }, { 2, 30, 40 },
    { 50, 50, 50 } };
  for (const auto& r : radii)
  {
    SCOPED_TRACE(testing::Message() << r.x << "," << r.y << "," << r.z);
    expectStatsMatchBruteForce(v, dims, r, vao::Region::whole(viewOf(v, dims)), 3);
  }
}

TYPED_TEST(BoxStatisticsTyped, WholeGroupsOfSixteenRowsAndTheirTails)
{
  // The extrema's x pass moves 16 rows at a time into lanes (16-bit voxels: 16 x 16 blocks
  // in AVX2 registers) and back: rows and columns past the last whole group or block, and
  // a region that starts off the first column. A y radius of 8 or more makes the bands of
  // rows (extremaBandRows) read groups of 16; an x radius of 0 leaves the x pass the
  // identity, so any misplaced value shows.
  const vao::Index3 dims = { 53, 37, 4 };
  const double lo = std::is_signed<TypeParam>::value ? -100 : 0;
  const auto v = randomVolume<TypeParam>(dims, lo, lo + 200, 29); // within 8-bit types too
  const vao::Region whole = vao::Region::whole(viewOf(v, dims));
  const vao::Region offset{ { 3, 1, 1 }, { 47, 34, 3 } };
  for (const vao::Radius& r :
    { vao::Radius{ 0, 8, 0 }, vao::Radius{ 1, 8, 1 }, vao::Radius{ 4, 9, 0 } })
  {
    SCOPED_TRACE(testing::Message() << r.x << "," << r.y << "," << r.z);
    expectStatsMatchBruteForce(v, dims, r, whole, 2);
    expectStatsMatchBruteForce(v, dims, r, offset, 1);
  }
}

TEST(BoxStatistics, SubRegionsAndThreadCounts)
{
  const vao::Index3 dims = { 19, 15, 21 };
  const auto v = randomVolume<std::int16_t>(dims, -1000, 1500, 3);
  const vao::Region regions[] = { { { 3, 2, 5 }, { 9, 7, 11 } }, { { 0, 14, 0 }, { 19, 1, 21 } },
    { { 18, 0, 20 }, { 1, 15, 1 } } };
  for (const auto& region : regions)
    for (int threads : { 1, 2, 5 })
      expectStatsMatchBruteForce(v, dims, { 4, 2, 3 }, region, threads);
}

TEST(BoxStatistics, ReadsOneComponentThroughTheStride)
{
  const vao::Index3 dims = { 9, 8, 7 };
  const auto scalar = randomVolume<float>(dims, -5, 5, 5);
  std::vector<float> interleaved(scalar.size() * 3, 1e30f);
  for (std::size_t i = 0; i < scalar.size(); ++i)
    interleaved[3 * i + 1] = scalar[i];
  const vao::Radius r{ 2, 3, 1 };
  const auto region = vao::Region::whole(viewOf(scalar, dims));
  StatsArrays a(region.voxelCount()), b(region.voxelCount());
  ASSERT_TRUE(vao::computeBoxStatistics(viewOf(scalar, dims), region, r, a.output()).ok);
  vao::VolumeView strided = viewOf(interleaved, dims, 3);
  strided.data = interleaved.data() + 1;
  ASSERT_TRUE(vao::computeBoxStatistics(strided, region, r, b.output()).ok);
  EXPECT_EQ(a.mean, b.mean);
  EXPECT_EQ(a.variance, b.variance);
  EXPECT_EQ(a.minimum, b.minimum);
  EXPECT_EQ(a.maximum, b.maximum);
}

/// Catastrophic cancellation: large offsets with small local deviations.
template <class T>
void expectVarianceOfOffsetNoise(double offset, double amplitude, bool integerNoise)
{
  const vao::Index3 dims = { 31, 29, 27 };
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> noise(-amplitude, amplitude);
  std::vector<T> v(dims[0] * dims[1] * dims[2]);
  for (auto& value : v)
    value = static_cast<T>(offset + (integerNoise ? std::round(noise(rng)) : noise(rng)));
  const vao::Radius r{ 5, 5, 5 };
  const auto region = vao::Region::whole(viewOf(v, dims));
  StatsArrays got(region.voxelCount());
  ASSERT_TRUE(vao::computeBoxStatistics(viewOf(v, dims), region, r, got.output()).ok);
  double worst = 0;
  std::int64_t k = 0;
  for (std::int64_t z = 0; z < dims[2]; z += 3)
    for (std::int64_t y = 0; y < dims[1]; y += 2)
      for (std::int64_t x = 0; x < dims[0]; ++x)
      {
        k = (z * dims[1] + y) * dims[0] + x;
        const auto ref = bruteForceStats(v, dims, r, x, y, z);
        worst = std::max(worst, std::abs(got.variance[k] - ref.variance));
        ASSERT_GT(ref.variance, 0.1);
      }
  EXPECT_LE(worst, 1e-3) << "worst absolute variance error";
}

TEST(BoxStatisticsPrecision, Int16At30000WithNoiseOfTwo)
{
  expectVarianceOfOffsetNoise<std::int16_t>(30000, 2, true);
}

TEST(BoxStatisticsPrecision, FloatAtOneMillionWithUnitDeviations)
{
  expectVarianceOfOffsetNoise<float>(1e6, 1.5, false);
}

TEST(BoxStatisticsPrecision, DoubleAtOneBillionWithUnitDeviations)
{
  expectVarianceOfOffsetNoise<double>(1e9, 1.5, false);
}

TEST(BoxStatisticsValidation, RejectsBadArguments)
{
  const vao::Index3 dims = { 5, 5, 5 };
  const auto v = randomVolume<float>(dims, 0, 1, 1);
  StatsArrays out(125);
  const auto whole = vao::Region::whole(viewOf(v, dims));
  EXPECT_FALSE(vao::computeBoxStatistics(viewOf(v, dims), whole, { -1, 1, 1 }, out.output()).ok);
  EXPECT_FALSE(
    vao::computeBoxStatistics(viewOf(v, { 0, 5, 5 }), whole, { 1, 1, 1 }, out.output()).ok);
  vao::Region outside{ { 3, 0, 0 }, { 5, 5, 5 } };
  EXPECT_FALSE(vao::computeBoxStatistics(viewOf(v, dims), outside, { 1, 1, 1 }, out.output()).ok);
  vao::VolumeView null = viewOf(v, dims);
  null.data = nullptr;
  EXPECT_FALSE(vao::computeBoxStatistics(null, whole, { 1, 1, 1 }, out.output()).ok);
}

TEST(BoxStatisticsExecution, HonoursCancellationAndReportsProgress)
{
  const vao::Index3 dims = { 20, 20, 40 };
  const auto v = randomVolume<std::uint8_t>(dims, 0, 255, 9);
  StatsArrays out(dims[0] * dims[1] * dims[2]);
  std::vector<double> progress;
  vao::Execution execution;
  execution.threads = 2;
  execution.progress = [&](double p) { progress.push_back(p); };
  const auto whole = vao::Region::whole(viewOf(v, dims));
  ASSERT_TRUE(
    vao::computeBoxStatistics(viewOf(v, dims), whole, { 2, 2, 2 }, out.output(), execution).ok);
  ASSERT_FALSE(progress.empty());
  EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end()));
  EXPECT_LE(progress.back(), 1.0);
  execution.abortRequested = [] { return true; };
  const vao::Status status =
    vao::computeBoxStatistics(viewOf(v, dims), whole, { 2, 2, 2 }, out.output(), execution);
  EXPECT_FALSE(status.ok);
  EXPECT_TRUE(status.aborted);
}

} // namespace

TEST(BoxStatistics, BandsOfRowsOnALargeVolumeMatchBruteForce)
{
  // With the extrema the region goes in bands of rows; each band's last row once read the
  // x sums of a row past the band (512x512x40 at R = 10 crashed). Every output checked
  // on a sample of voxels, the bands' first and last rows included.
  const vao::Index3 dims = { 512, 512, 40 };
  const auto v = randomVolume<std::int16_t>(dims, -1000, 1000, 23);
  const vao::Radius r{ 10, 10, 10 };
  const vao::Region region{ { 0, 0, 0 }, dims };
  StatsArrays got(region.voxelCount());
  const vao::Status status = vao::computeBoxStatistics(viewOf(v, dims), region, r, got.output());
  ASSERT_TRUE(status.ok) << status.message;
  for (std::int64_t y : { 0, 31, 32, 33, 255, 479, 480, 511 })
    for (std::int64_t x : { 0, 7, 300, 511 })
      for (std::int64_t z : { 0, 19, 39 })
      {
        const std::int64_t k = (z * dims[1] + y) * dims[0] + x;
        const ReferenceStats ref = bruteForceStats(v, dims, r, x, y, z);
        ASSERT_EQ(got.minimum[k], ref.minimum) << x << "," << y << "," << z;
        ASSERT_EQ(got.maximum[k], ref.maximum) << x << "," << y << "," << z;
        ASSERT_TRUE(closeRelative(got.mean[k], ref.mean, 1e-9)) << x << "," << y << "," << z;
        ASSERT_TRUE(closeRelative(got.variance[k], ref.variance, 1e-9))
          << x << "," << y << "," << z;
      }
}

namespace
{

/// A flat volume of `value` in boxes of `radius` (in x and y; the volume is one slice):
/// every mean must be `value` exactly and every variance 0, as exact integer sums give them.
template <class T>
void expectFlatExact(T value, std::int64_t side, int radius)
{
  const vao::Index3 dims = { side, side, 1 };
  const std::vector<T> v(side * side, value);
  StatsArrays got(side * side);
  const vao::Region whole = vao::Region::whole(viewOf(v, dims));
  ASSERT_TRUE(
    vao::computeBoxStatistics(viewOf(v, dims), whole, { radius, radius, 0 }, got.output()).ok);
  std::int64_t failures = 0;
  for (std::int64_t k = 0; k < side * side; ++k)
    if ((got.mean[k] != double(value) || got.variance[k] != 0.0) && failures++ < 5)
      ADD_FAILURE() << "radius " << radius << ", voxel " << k << ": mean " << got.mean[k]
                    << ", variance " << got.variance[k] << ", count " << got.count[k];
}

} // namespace

// Sums of v run in 32 bits where every box sum fits int32 whatever the values (R = 90 on
// uint16's largest value, 181^2 voxels, and R = 127 on int16's smallest, 255^2) and in 64
// bits just beyond (R = 91 and 128, whose sums would overflow int32).
TEST(BoxStatistics, SumsExactOnBothSidesOfTheirThirtyTwoBitLimit)
{
  expectFlatExact<std::uint16_t>(65535, 200, 90);
  expectFlatExact<std::uint16_t>(65535, 200, 91);
  expectFlatExact<std::int16_t>(-32768, 300, 127);
  expectFlatExact<std::int16_t>(-32768, 300, 128);
  // A row whose running sums pass 2^32 (more than 65537 voxels of 65535) and wrap.
  const vao::Index3 dims = { 100000, 1, 1 };
  std::vector<std::uint16_t> row(dims[0]);
  std::mt19937 rng(5);
  for (auto& value : row)
    value = rng() % 8 ? 65535 : 0;
  expectStatsMatchBruteForce(row, dims, { 3, 0, 0 }, vao::Region::whole(viewOf(row, dims)), 2);
}

// The x sums of squares of 8-bit and int16 rows run in 32 bits where no window's sum can
// leave int32's range (the row's greatest |a^2 - b^2| times the window's width below
// 2^31), and in 64 bits otherwise: 5 x 20724^2 is just below 2^31, 5 x 20725^2 just above
// (below 2^32, so that only the right limit keeps it exact). Values of two neighbours, so
// that a wrapped sum shows in the variance (a flat box's would be clamped to 0).
TEST(BoxStatistics, SquaresExactOnBothSidesOfTheirThirtyTwoBitLimit)
{
  const vao::Index3 dims = { 40, 6, 3 };
  for (const int value : { 20724, 20725, -20724, -20725 })
  {
    SCOPED_TRACE(value);
    std::mt19937 rng(value + 50000);
    std::vector<std::int16_t> v(dims[0] * dims[1] * dims[2]);
    for (auto& x : v)
      x = static_cast<std::int16_t>(rng() % 2 ? value : value - (value > 0 ? 1 : -1));
    expectStatsMatchBruteForce(v, dims, { 2, 1, 1 }, vao::Region::whole(viewOf(v, dims)), 2);
  }
  // Rows of small values (32-bit squares) among rows of int16's ends (64-bit ones).
  const vao::Index3 mixedDims = { 37, 9, 5 };
  auto v = randomVolume<std::int16_t>(mixedDims, -100, 100, 41);
  std::mt19937 rng(42);
  for (std::int64_t y = 0; y < mixedDims[1]; y += 3)
    for (std::int64_t x = 0; x < mixedDims[0]; ++x)
      v[(2 * mixedDims[1] + y) * mixedDims[0] + x] = rng() % 2 ? 32767 : -32768;
  for (const vao::Radius r : { vao::Radius{ 2, 1, 1 }, vao::Radius{ 6, 2, 2 } })
    expectStatsMatchBruteForce(v, mixedDims, r, vao::Region::whole(viewOf(v, mixedDims)), 2);
}
