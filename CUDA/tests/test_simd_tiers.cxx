// The row loops built for several instruction sets (CpuDispatch.h). The AVX2 and AVX-512
// builds both contract multiply-adds, so they must give the same numbers bit for bit, on
// sizes that leave every remainder of a 4- or 8-wide vector; the baseline build has no
// FMA and rounds a little differently, so it is held to the brute-force reference (and
// the integer loops to bit equality). On a processor without AVX2 or AVX-512 the higher
// tiers fall back to the ones below, and the comparisons still run.
#include "PyramidTestSupport.h"
#include "ResultComparison.h"

#include "cpu/box_statistics/RunningTotals.h"
#include "cpu/simd/CpuDispatch.h"

#include "vao/HistogramCdf.h"

#include <gtest/gtest.h>

#include <random>

using namespace vaotest;
using vao::detail::SimdTier;

namespace
{

const SimdTier kTiers[] = { SimdTier::Baseline, SimdTier::Avx2, SimdTier::Avx512 };

/// Lifts the cap again when a test ends, whatever it asserted.
struct TierCap
{
  explicit TierCap(SimdTier limit) { vao::detail::limitSimdTier(limit); }
  ~TierCap() { vao::detail::limitSimdTier(SimdTier::Avx512); }
};

template <class T>
std::vector<vao::MomentLevel> pyramidAtTier(
  SimdTier tier, const std::vector<T>& v, const vao::Index3& d, bool half)
{
  const TierCap cap(tier);
  vao::PyramidParameters p;
  p.levels = 3;
  p.startAtHalfResolution = half;
  std::vector<vao::MomentLevel> pyramid;
  const vao::Status s = vao::buildMomentPyramid(viewOf(v, d), { 0, 0, 0 }, { 1, 1, 1 }, p, pyramid);
  EXPECT_TRUE(s.ok) << s.message;
  return pyramid;
}

template <class T>
void expectPyramidTiersEqual(const vao::Index3& d, double lo, double hi)
{
  const auto v = randomVolume<T>(d, lo, hi, 23u);
  for (bool half : { false, true })
  {
    const auto ref = refPyramid(v, d, 3, half, 0.0);
    for (SimdTier tier : kTiers)
    {
      expectLevelsMatch(pyramidAtTier(tier, v, d, half), ref, 0.0, 1e-5, 1e-4, 1e-6);
    }
    const auto avx2 = pyramidAtTier(SimdTier::Avx2, v, d, half);
    const auto avx512 = pyramidAtTier(SimdTier::Avx512, v, d, half);
    ASSERT_EQ(avx2.size(), 3u);
    ASSERT_EQ(avx512.size(), avx2.size());
    for (std::size_t l = 0; l < avx2.size(); ++l)
    {
      const auto bits = [](const vao::LevelArray& a)
      { return std::vector<float>(a.begin(), a.end()); };
      EXPECT_TRUE(sameBits(bits(avx512[l].mean), bits(avx2[l].mean)))
        << "mean, level " << l << ", half " << half;
      EXPECT_TRUE(sameBits(bits(avx512[l].variance), bits(avx2[l].variance)))
        << "variance, level " << l << ", half " << half;
    }
  }
}

std::vector<float> opennessAtTier(SimdTier tier, const vao::VolumeView& view, vao::Method method,
  const std::vector<double>& thresholds, vao::QueryMode query = vao::QueryMode::VoxelValue,
  double iso = 0.0)
{
  const TierCap cap(tier);
  vao::AmbientOcclusionParameters p;
  p.method = method;
  p.radius = { 3, 2, 4 };
  p.thresholds = thresholds;
  p.queryMode = query;
  p.isoValue = iso;
  const vao::Region region = vao::Region::whole(view);
  std::vector<float> out(static_cast<std::size_t>(region.voxelCount()), -1.0f);
  const vao::Status s = vao::computeAmbientOcclusion(view, region, p, { out.data(), nullptr });
  EXPECT_TRUE(s.ok) << s.message;
  return out;
}

/// The box statistics (with the extrema: van Herk rows on vectors) at one tier.
template <class T>
std::vector<std::vector<double>> boxStatisticsAtTier(
  SimdTier tier, const std::vector<T>& v, const vao::Index3& d)
{
  const TierCap cap(tier);
  const vao::Region region{ { 1, 2, 0 }, { d[0] - 2, d[1] - 3, d[2] - 1 } };
  std::vector<std::vector<double>> fields(
    5, std::vector<double>(static_cast<std::size_t>(region.voxelCount())));
  const vao::BoxStatisticsOutput out{ fields[0].data(), fields[1].data(), fields[2].data(),
    fields[3].data(), fields[4].data() };
  const vao::Status s = vao::computeBoxStatistics(viewOf(v, d), region, { 4, 2, 3 }, out);
  EXPECT_TRUE(s.ok) << s.message;
  return fields;
}

template <class T>
void expectBoxStatisticsTiersEqual(const vao::Index3& d, double lo, double hi)
{
  const auto v = randomVolume<T>(d, lo, hi, 31u);
  const auto baseline = boxStatisticsAtTier(SimdTier::Baseline, v, d);
  for (SimdTier tier : kTiers)
  {
    const auto fields = boxStatisticsAtTier(tier, v, d);
    for (std::size_t f = 0; f < fields.size(); ++f)
      EXPECT_TRUE(sameBits(fields[f], baseline[f])) << "field " << f << ", tier " << int(tier);
  }
}

} // namespace

TEST(SimdTiers, CapLowersTheTier)
{
  const SimdTier best = vao::detail::cpuSimdTier();
  {
    const TierCap cap(SimdTier::Baseline);
    EXPECT_EQ(vao::detail::cpuSimdTier(), SimdTier::Baseline);
    EXPECT_FALSE(vao::detail::cpuHasAvx2());
  }
  {
    const TierCap cap(SimdTier::Avx2);
    EXPECT_LE(vao::detail::cpuSimdTier(), SimdTier::Avx2);
    EXPECT_EQ(vao::detail::cpuHasAvx2(), best >= SimdTier::Avx2);
  }
  EXPECT_EQ(vao::detail::cpuSimdTier(), best);
}

TEST(SimdTiers, PyramidLevelsOfEveryTier)
{
  // x = 37 and 18: interiors of odd length after the clipped ends, and an x pass with
  // fewer voxels than one AVX-512 vector at level 2.
  expectPyramidTiersEqual<std::int16_t>({ 37, 11, 9 }, -1200.0, 3000.0);
  expectPyramidTiersEqual<std::uint8_t>({ 18, 13, 7 }, 0.0, 255.0);
  expectPyramidTiersEqual<float>({ 29, 6, 10 }, -3.0, 7.0);
}

TEST(SimdTiers, BoxStatisticsAndExtremaEqualTheBaselineBitForBit)
{
  // 37 rows: two groups of 16 in the x pass of the extrema and a remainder of 5.
  expectBoxStatisticsTiersEqual<std::int16_t>({ 29, 40, 9 }, -1200.0, 3000.0);
  expectBoxStatisticsTiersEqual<std::uint8_t>({ 18, 21, 7 }, 0.0, 255.0);
  expectBoxStatisticsTiersEqual<float>({ 23, 19, 6 }, -3.0, 7.0);
  expectBoxStatisticsTiersEqual<double>({ 9, 35, 5 }, -1e6, 1e6);
}

/// A random int16 volume of `d` and its Histogram CDF thresholds (16 bins).
struct ScanWithThresholds
{
  std::vector<std::int16_t> values;
  vao::VolumeView view;
  std::vector<double> thresholds;

  ScanWithThresholds(const vao::Index3& d, double lo, double hi, unsigned seed)
    : values(randomVolume<std::int16_t>(d, lo, hi, seed))
    , view(viewOf(values, d))
  {
    const vao::Status s = vao::volumeThresholds(this->view, 16, this->thresholds);
    EXPECT_TRUE(s.ok) << s.message;
  }
};

/// The openness of `method` at every tier equals the baseline's, bit for bit.
void expectOpennessTiersEqual(const vao::VolumeView& view, vao::Method method,
  const std::vector<double>& thresholds, vao::QueryMode query = vao::QueryMode::VoxelValue,
  double iso = 0.0)
{
  const auto baseline = opennessAtTier(SimdTier::Baseline, view, method, thresholds, query, iso);
  for (SimdTier tier : kTiers)
  {
    EXPECT_TRUE(sameBits(opennessAtTier(tier, view, method, thresholds, query, iso), baseline))
      << "method " << int(method) << ", query " << int(query) << ", iso " << iso << ", tier "
      << int(tier);
  }
}

TEST(SimdTiers, BoxEstimatorsAndHistogramEqualTheBaselineBitForBit)
{
  const ScanWithThresholds scan({ 27, 14, 11 }, -1000.0, 2000.0, 5u);
  ASSERT_FALSE(scan.thresholds.empty());
  // The box sums and the histogram's channels are integer loops; the estimators that run
  // on those tiers take them and must agree.
  expectOpennessTiersEqual(scan.view, vao::Method::Chebyshev, scan.thresholds);
  expectOpennessTiersEqual(scan.view, vao::Method::HistogramCdf, scan.thresholds);
}

TEST(SimdTiers, HistogramCdfOfEveryQueryCaseEqualsTheBaselineBitForBit)
{
  // Iso queries below the first threshold, on one, between two, on and past the last;
  // the smoothed query lands anywhere in between.
  const ScanWithThresholds scan({ 23, 9, 8 }, -500.0, 900.0, 9u);
  const std::vector<double>& t = scan.thresholds;
  ASSERT_EQ(t.size(), 16u);
  const double isoValues[] = { t.front() - 1.0, t[3], 0.5 * (t[5] + t[6]), t.back(),
    t.back() + 1.0 };
  for (double iso : isoValues)
    expectOpennessTiersEqual(
      scan.view, vao::Method::HistogramCdf, t, vao::QueryMode::IsoValue, iso);
  expectOpennessTiersEqual(scan.view, vao::Method::HistogramCdf, t, vao::QueryMode::SmoothedValue);
}

// The box sums' running totals (RunningTotals.h) on every tier against the totals summed
// one by one here: lengths around the 8-wide vector, values up to 2^40 of either sign; one
// row alone as well, and the 32-bit totals, which wrap modulo 2^32.
TEST(SimdTiers, RunningTotalsEqualTheSumsOneByOne)
{
  std::mt19937_64 rng(31);
  for (const SimdTier tier : kTiers)
  {
    for (std::int64_t n = 0; n <= 70; ++n)
    {
      std::vector<std::int64_t> a(n), b(n), expectedA(n), expectedB(n);
      std::int64_t totalA = 0, totalB = 0;
      for (std::int64_t i = 0; i < n; ++i)
      {
        a[i] =
          static_cast<std::int64_t>(rng() % (std::uint64_t(1) << 41)) - (std::int64_t(1) << 40);
        b[i] = static_cast<std::int64_t>(rng() % 1000);
        expectedA[i] = totalA += a[i];
        expectedB[i] = totalB += b[i];
      }
      // Capped like every loop here: a tier the processor lacks runs the best it has.
      const TierCap cap(tier);
      std::vector<std::int64_t> single = a; // one row alone (no second row)
      std::vector<std::uint32_t> narrow(n), narrowB(n), expectedNarrow(n), expectedNarrowB(n);
      std::uint32_t totalNarrow = 0, totalNarrowB = 0;
      for (std::int64_t i = 0; i < n; ++i)
      {
        narrow[i] = static_cast<std::uint32_t>(rng()); // the totals wrap modulo 2^32
        narrowB[i] = static_cast<std::uint32_t>(rng() % 5);
        expectedNarrow[i] = totalNarrow += narrow[i];
        expectedNarrowB[i] = totalNarrowB += narrowB[i];
      }
      std::vector<std::uint32_t> narrowSingle = narrow;
      vao::detail::runningTotals(a.data(), b.data(), n, vao::detail::cpuSimdTier());
      vao::detail::runningTotals(single.data(), nullptr, n, vao::detail::cpuSimdTier());
      vao::detail::runningTotals(narrow.data(), narrowB.data(), n, vao::detail::cpuSimdTier());
      vao::detail::runningTotals(narrowSingle.data(), nullptr, n, vao::detail::cpuSimdTier());
      ASSERT_EQ(a, expectedA) << "tier " << static_cast<int>(tier) << ", n " << n;
      ASSERT_EQ(b, expectedB) << "tier " << static_cast<int>(tier) << ", n " << n;
      ASSERT_EQ(single, expectedA) << "one row, tier " << static_cast<int>(tier) << ", n " << n;
      ASSERT_EQ(narrow, expectedNarrow)
        << "32 bits, tier " << static_cast<int>(tier) << ", n " << n;
      ASSERT_EQ(narrowB, expectedNarrowB)
        << "32 bits, second row, tier " << static_cast<int>(tier) << ", n " << n;
      ASSERT_EQ(narrowSingle, expectedNarrow)
        << "32 bits, one row, tier " << static_cast<int>(tier) << ", n " << n;
    }
  }
}
