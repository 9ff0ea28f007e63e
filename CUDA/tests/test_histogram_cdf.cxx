// Histogram CDF (docs/methods.md section 8): the thresholds' properties, and the openness against a
// brute force of the definition (ReferenceFormulas.h) on random volumes of every kind.
#include "HistogramTestSupport.h"
#include "ReferenceFormulas.h"
#include "TestVolumes.h"

#include "cpu/histogram_cdf/HistogramBins.h"

#include "vao/HistogramCdf.h"
#include "vao/Validation.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <random>
#include <set>

using namespace vaotest;

namespace
{

template <class T>
std::set<double> distinctValues(const std::vector<T>& v)
{
  std::set<double> values;
  for (const T x : v)
    values.insert(static_cast<double>(x));
  return values;
}

} // namespace

TEST(HistogramCdf, ThresholdsSpanTheDataAndAscend)
{
  const vao::Index3 dims = { 23, 19, 17 };
  const auto v = randomVolume<std::int16_t>(dims, -1024, 3000, 5);
  const auto values = distinctValues(v);
  for (int bins : { 2, 3, 16, 64, 1024 })
  {
    std::vector<double> t;
    ASSERT_TRUE(vao::volumeThresholds(viewOf(v, dims), bins, t).ok);
    ASSERT_EQ(t.size(), std::min<size_t>(bins, values.size())) << bins;
    EXPECT_EQ(t.front(), *values.begin());
    EXPECT_EQ(t.back(), *values.rbegin());
    for (size_t k = 1; k < t.size(); ++k)
      EXPECT_LT(t[k - 1], t[k]);
    for (const double x : t)
      EXPECT_EQ(values.count(x), 1u) << "a threshold that is not a value of the data: " << x;
  }
}

TEST(HistogramCdf, ATieCostsOneThreshold)
{
  // 80% of the voxels at 0 (air clamped), the rest spread over 1..2000.
  const vao::Index3 dims = { 40, 40, 40 };
  std::vector<std::int16_t> v(dims[0] * dims[1] * dims[2], 0);
  std::mt19937 rng(3);
  for (size_t i = 0; i < v.size(); ++i)
    if (rng() % 5 == 0)
      v[i] = static_cast<std::int16_t>(1 + rng() % 2000);
  std::vector<double> t;
  ASSERT_TRUE(vao::volumeThresholds(viewOf(v, dims), 32, t).ok);
  ASSERT_EQ(t.size(), 32u);
  EXPECT_EQ(t[0], 0.0);
  // The other 31 share the spread values: no threshold is spent twice on the tie.
  EXPECT_GT(t[1], 0.0);
  std::vector<std::int64_t> perBin(t.size(), 0);
  for (const auto x : v)
    if (x > 0)
      ++perBin[std::lower_bound(t.begin(), t.end(), double(x)) - t.begin()];
  for (size_t k = 2; k + 1 < t.size(); ++k)
    EXPECT_LT(perBin[k], 13 * static_cast<std::int64_t>(v.size()) / 50 / 31)
      << "bin " << k << " holds too much";
}

TEST(HistogramCdf, SummariesOfPartsMergeToTheWholeVolumes)
{
  const vao::Index3 dims = { 21, 13, 30 };
  for (int kind = 0; kind < 2; ++kind)
  {
    const auto vi = randomVolume<std::int32_t>(dims, -70000, 90000, 8);
    const auto vf = randomVolume<float>(dims, -3.5e6, 1e7, 9);
    const vao::VolumeView view = kind == 0 ? viewOf(vi, dims) : viewOf(vf, dims);
    const auto range = vao::valueRange(view);
    auto whole = vao::ValueHistogram::forRange(view.type, range[0], range[1]);
    ASSERT_TRUE(vao::addToValueHistogram(view, vao::Region::whole(view), whole).ok);
    EXPECT_EQ(whole.totalCount(), view.voxelCount());
    // Three slabs in another order, merged.
    auto merged = vao::ValueHistogram::forRange(view.type, range[0], range[1]);
    for (const auto& slab : { std::array<std::int64_t, 2>{ 20, 10 }, { 0, 7 }, { 7, 13 } })
    {
      auto part = vao::ValueHistogram::forRange(view.type, range[0], range[1]);
      ASSERT_TRUE(
        vao::addToValueHistogram(view, { { 0, 0, slab[0] }, { dims[0], dims[1], slab[1] } }, part)
          .ok);
      merged.merge(part);
    }
    for (int bins : { 5, 64, 300 })
      EXPECT_EQ(vao::histogramThresholds(merged, bins), vao::histogramThresholds(whole, bins));
  }
}

namespace
{

/// The cell of a finite value as vao/HistogramCdf.h defines it: one per integer from the
/// lowest value, or equal cells over the range (in long double, where the width of a
/// range of the largest doubles does not overflow).
std::int64_t definedCell(const vao::ValueHistogram& h, double value)
{
  const auto cells = static_cast<std::int64_t>(h.counts.size());
  if (h.integerCells)
    return static_cast<std::int64_t>(value - h.lowest);
  if (cells == 1)
    return 0;
  const long double at = (static_cast<long double>(value) - h.lowest) /
    (static_cast<long double>(h.highest) - h.lowest) * cells;
  return std::min<std::int64_t>(cells - 1, static_cast<std::int64_t>(std::floor(at)));
}

/// addToValueHistogram's counts and extrema against a voxel-by-voxel tally over the
/// defined cells, on a sub-region of every other voxel (a stride of 2).
template <class T>
void expectCellsHoldTheirValues(std::vector<T> v, const vao::Index3& dims)
{
  const auto view = viewOf(v, dims, 2);
  double lo = INFINITY, hi = -INFINITY;
  for (std::size_t i = 0; i < v.size(); i += 2)
    if (std::isfinite(double(v[i])))
      lo = std::min(lo, double(v[i])), hi = std::max(hi, double(v[i]));
  const vao::Region region{ { 1, 2, 1 }, { dims[0] - 2, dims[1] - 3, dims[2] - 1 } };
  auto got = vao::ValueHistogram::forRange(view.type, lo, hi);
  auto expected = got;
  ASSERT_TRUE(vao::addToValueHistogram(view, region, got).ok);
  for (std::int64_t z = 1; z < dims[2]; ++z)
    for (std::int64_t y = 2; y < dims[1] - 1; ++y)
      for (std::int64_t x = 1; x < dims[0] - 1; ++x)
      {
        const double value = double(v[2 * ((z * dims[1] + y) * dims[0] + x)]);
        if (!std::isfinite(value))
          continue;
        const std::int64_t c = definedCell(expected, value);
        EXPECT_EQ(c, expected.cell(value)) << value;
        ++expected.counts[c];
        expected.minimum[c] = std::min(expected.minimum[c], value);
        expected.maximum[c] = std::max(expected.maximum[c], value);
      }
  EXPECT_EQ(got.counts, expected.counts);
  EXPECT_EQ(got.minimum, expected.minimum);
  EXPECT_EQ(got.maximum, expected.maximum);
}

} // namespace

TEST(HistogramCdf, ValueSummaryCellsHoldTheirValues)
{
  const vao::Index3 dims = { 37, 11, 9 }, twice = { 2 * 37, 11, 9 };
  auto f = randomVolume<float>(twice, -3.5e6, 1e7, 3);
  f[10] = NAN;
  f[12] = -INFINITY;
  expectCellsHoldTheirValues(f, dims);
  expectCellsHoldTheirValues(randomVolume<float>(twice, 0.0, 1e-40, 4), dims); // subnormal
  expectCellsHoldTheirValues(std::vector<float>(twice[0] * 11 * 9, 2.5f), dims);
  expectCellsHoldTheirValues(randomVolume<double>(twice, -1.7e308, 1.7e308, 5), dims);
  expectCellsHoldTheirValues(randomVolume<std::int32_t>(twice, -70000, 90000, 6), dims);
  expectCellsHoldTheirValues(randomVolume<std::int32_t>(twice, -700, 900, 7), dims);
  expectCellsHoldTheirValues(randomVolume<std::uint32_t>(twice, 0, 4e9, 8), dims);
  expectCellsHoldTheirValues(randomVolume<std::int64_t>(twice, -9e18, 9e18, 9), dims);
}

TEST(HistogramCdf, MatchesTheDefinitionOnRandomVolumes)
{
  const vao::Index3 dims = { 17, 11, 9 };
  const auto v8 = randomVolume<std::uint8_t>(dims, 0, 255, 31);
  const auto v16 = randomVolume<std::int16_t>(dims, -1024, 1600, 32);
  const auto vf = randomVolume<float>(dims, -1, 1, 33);
  const auto vd = randomVolume<double>(dims, -1e9, 1e9, 34);
  const auto vu32 = randomVolume<std::uint32_t>(dims, 0, 4e9, 35);
  for (int bins : { 2, 7, 64 })
  {
    SCOPED_TRACE(bins);
    std::vector<double> t8, t16, tf, td, tu;
    ASSERT_TRUE(vao::volumeThresholds(viewOf(v8, dims), bins, t8).ok);
    ASSERT_TRUE(vao::volumeThresholds(viewOf(v16, dims), bins, t16).ok);
    ASSERT_TRUE(vao::volumeThresholds(viewOf(vf, dims), bins, tf).ok);
    ASSERT_TRUE(vao::volumeThresholds(viewOf(vd, dims), bins, td).ok);
    ASSERT_TRUE(vao::volumeThresholds(viewOf(vu32, dims), bins, tu).ok);
    for (int r = 1; r <= 4; r += 3)
    {
      expectMatchesDefinition(v8, dims, { r, r, r }, t8);
      expectMatchesDefinition(v16, dims, { r, r, r }, t16);
      expectMatchesDefinition(vf, dims, { r, r, r }, tf);
      expectMatchesDefinition(vd, dims, { r, r, r }, td);
      expectMatchesDefinition(vu32, dims, { r, r, r }, tu);
    }
    expectMatchesDefinition(v16, dims, { 3, 0, 2 }, t16);
    expectMatchesDefinition(v16, dims, { 30, 30, 30 }, t16);
    expectMatchesDefinition(vf, dims, { 2, 2, 2 }, tf, vao::QueryMode::IsoValue, 0.3);
    expectMatchesDefinition(vf, dims, { 2, 2, 2 }, tf, vao::QueryMode::IsoValue, -5.0);
    expectMatchesDefinition(vf, dims, { 2, 2, 2 }, tf, vao::QueryMode::IsoValue, 5.0);
  }
  // Thresholds that are not values of the data, nor span it.
  expectMatchesDefinition(v16, dims, { 2, 3, 1 }, { -500.5, 0.25, 1.0, 700.0 });
}

TEST(HistogramCdf, SixteenBitCountsWrapSafelyAndWideBoxesUseWiderLanes)
{
  // 39^3 = 59319 voxels fit 16-bit lanes; 41^3 = 68921 do not.
  const vao::Index3 dims = { 48, 45, 44 };
  const auto v = randomVolume<std::uint8_t>(dims, 0, 40, 41);
  std::vector<double> t;
  ASSERT_TRUE(vao::volumeThresholds(viewOf(v, dims), 16, t).ok);
  for (int r : { 19, 20 })
  {
    const auto view = viewOf(v, dims);
    const auto got = histogramOpenness(view, vao::Region::whole(view), { r, r, r }, t);
    for (std::int64_t k = 0; k < view.voxelCount(); k += 997)
    {
      const std::int64_t x = k % dims[0], y = (k / dims[0]) % dims[1], z = k / (dims[0] * dims[1]);
      const double expected = reference::histogramCdf(double(v[k]), t,
        [&](double th) {
          return fractionAtOrBelow(v, dims, { r, r, r }, x, y, z, th);
        });
      ASSERT_NEAR(got[k], expected, 2e-6) << "r " << r << " voxel " << k;
    }
  }
}

TEST(HistogramCdf, AtMostKDistinctValuesGiveExactBox)
{
  const vao::Index3 dims = { 19, 23, 14 };
  auto v8 = randomVolume<std::uint8_t>(dims, 0, 256, 51);
  auto vf = randomVolume<float>(dims, 0, 10, 52);
  for (auto& x : vf)
    x = std::floor(x) * 0.37f - 1.0f; // 10 distinct floats
  auto v16 = randomVolume<std::int16_t>(dims, -1000, 1000, 53);
  for (auto& x : v16)
    x = static_cast<std::int16_t>(x / 50 * 50); // 41 distinct values
  auto check = [&](auto& v, int bins)
  {
    const auto view = viewOf(v, dims);
    std::vector<double> t;
    ASSERT_TRUE(vao::volumeThresholds(view, bins, t).ok);
    const vao::Radius r{ 3, 2, 4 };
    const auto got = histogramOpenness(view, vao::Region::whole(view), r, t);
    std::vector<float> exact(view.voxelCount());
    vao::AmbientOcclusionParameters p;
    p.method = vao::Method::ExactBox;
    p.radius = r;
    ASSERT_TRUE(
      vao::computeAmbientOcclusion(view, vao::Region::whole(view), p, { exact.data(), nullptr })
        .ok);
    for (std::int64_t k = 0; k < view.voxelCount(); ++k)
      ASSERT_NEAR(got[k], exact[k], 1e-6) << k;
  };
  check(v8, 256);
  check(vf, 10);
  check(v16, 64);
}

TEST(HistogramCdf, APieceGrownByTheRadiusGivesTheWholeVolumesNumbers)
{
  const vao::Index3 dims = { 60, 21, 33 };
  const auto v = randomVolume<std::int16_t>(dims, -1024, 2000, 61);
  const auto view = viewOf(v, dims);
  std::vector<double> t;
  ASSERT_TRUE(vao::volumeThresholds(view, 64, t).ok);
  const vao::Radius r{ 5, 3, 4 };
  const auto whole = histogramOpenness(view, vao::Region::whole(view), r, t);
  // The piece x in [20, 50), z in [10, 20), grown by the radius, as its own block.
  const vao::Index3 lo = { 15, 0, 6 }, hi = { 55, 21, 24 };
  const vao::Index3 pd = { hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2] };
  std::vector<std::int16_t> piece;
  for (std::int64_t z = lo[2]; z < hi[2]; ++z)
    for (std::int64_t y = lo[1]; y < hi[1]; ++y)
      for (std::int64_t x = lo[0]; x < hi[0]; ++x)
        piece.push_back(v[(z * dims[1] + y) * dims[0] + x]);
  const vao::Region region{ { 5, 0, 4 }, { 30, 21, 10 } };
  const auto got = histogramOpenness(viewOf(piece, pd), region, r, t);
  std::int64_t k = 0;
  for (std::int64_t z = 10; z < 20; ++z)
    for (std::int64_t y = 0; y < 21; ++y)
      for (std::int64_t x = 20; x < 50; ++x, ++k)
        ASSERT_EQ(got[k], whole[(z * dims[1] + y) * dims[0] + x]) << x << "," << y << "," << z;
}

TEST(HistogramCdf, RefusesBadThresholdsAndBins)
{
  const vao::Index3 dims = { 8, 8, 8 };
  const auto v = randomVolume<float>(dims, 0, 1, 71);
  const auto view = viewOf(v, dims);
  std::vector<float> out(view.voxelCount());
  vao::AmbientOcclusionParameters p;
  p.method = vao::Method::HistogramCdf;
  p.radius = { 2, 2, 2 };
  const double nan = std::numeric_limits<double>::quiet_NaN();
  for (const auto& t :
    std::vector<std::vector<double>>{ {}, { 0.5, 0.2 }, { 0.1, 0.1 }, { 0.0, nan },
      { -std::numeric_limits<double>::infinity(), 1.0 }, std::vector<double>(1025, 0.0) })
  {
    p.thresholds = t;
    const vao::Status status =
      vao::computeAmbientOcclusion(view, vao::Region::whole(view), p, { out.data(), nullptr });
    EXPECT_FALSE(status.ok);
    EXPECT_NE(status.message.find("threshold"), std::string::npos) << status.message;
  }
  for (int bins : { -1, 0, 1, 1025, 1 << 30 })
    EXPECT_NE(vao::checkHistogramBins(bins).find("NumberOfBins"), std::string::npos) << bins;
  for (int bins : { 2, 64, 1024 })
    EXPECT_EQ(vao::checkHistogramBins(bins), "");
  // Non-finite data: the thresholds refuse it with the count.
  auto bad = v;
  bad[100] = nan;
  std::vector<double> t;
  const vao::Status status = vao::volumeThresholds(viewOf(bad, dims), 64, t);
  EXPECT_FALSE(status.ok);
  EXPECT_EQ(status.nonFiniteCount, 1);
}

TEST(HistogramCdf, ExtremeMagnitudesKeepTheirCells)
{
  // Values at the edges of double: the cell grid's width must not overflow.
  const vao::Index3 dims = { 6, 5, 4 };
  std::vector<double> v(dims[0] * dims[1] * dims[2]);
  for (size_t i = 0; i < v.size(); ++i)
    v[i] = (i % 3 == 0 ? -1.7e308 : (i % 3 == 1 ? 1.7e308 : 4.9e-324 * double(i)));
  std::vector<double> t;
  ASSERT_TRUE(vao::volumeThresholds(viewOf(v, dims), 8, t).ok);
  EXPECT_EQ(t.front(), -1.7e308);
  EXPECT_EQ(t.back(), 1.7e308);
  expectMatchesDefinition(v, dims, { 1, 1, 1 }, t);
}

namespace
{

/// The bins BinOf gives a row of `values` (all its lengths up to one more than two
/// vectors, so every remainder), in 16 and 8 bits, against a count of the thresholds
/// below each value.
template <class T>
void expectRowBinsCountThresholds(
  const std::vector<T>& values, const std::vector<double>& thresholds)
{
  using vao::detail::SimdTier;
  for (SimdTier tier : { SimdTier::Baseline, vao::detail::cpuSimdTier() })
  {
    const vao::detail::BinOf<T> bin(thresholds, tier);
    for (std::size_t n : { values.size(), std::size_t(1), std::size_t(33), std::size_t(65) })
    {
      n = std::min(n, values.size());
      std::vector<std::uint16_t> got(n, 0xFFFF);
      bin.row(values.data(), 1, static_cast<std::int64_t>(n), got.data());
      std::vector<std::uint8_t> narrow(n, 0xFF); // as the ring of the default 64 bins holds them
      bin.row(values.data(), 1, static_cast<std::int64_t>(n), narrow.data());
      EXPECT_TRUE(std::equal(got.begin(), got.end(), narrow.begin())) << "8-bit bins";
      int failures = 0;
      for (std::size_t i = 0; i < n; ++i)
      {
        int below = 0;
        for (const double t : thresholds)
          below += t < static_cast<double>(values[i]) ? 1 : 0;
        if (got[i] != below && failures++ < 4)
          ADD_FAILURE() << "value " << +values[i] << ": bin " << got[i] << ", " << below
                        << " thresholds below it (tier " << int(tier) << ")";
      }
    }
  }
}

/// Every value of an 8- or 16-bit type's range near its ends and around the thresholds,
/// and random ones; for floats, random values and the thresholds' neighbours.
template <class T>
std::vector<T> probeValues(const std::vector<double>& thresholds, unsigned seed)
{
  std::mt19937 rng(seed);
  std::vector<T> values;
  const double lo = static_cast<double>(std::numeric_limits<T>::lowest());
  const double hi = static_cast<double>(std::numeric_limits<T>::max());
  for (double t : thresholds)
    for (double d : { -1.0, -0.5, 0.0, 0.5, 1.0 })
      if (t + d >= lo && t + d <= hi)
      {
        values.push_back(static_cast<T>(t + d));
        if (std::is_floating_point<T>::value)
        {
          values.push_back(std::nextafter(static_cast<T>(t), std::numeric_limits<T>::infinity()));
          values.push_back(std::nextafter(static_cast<T>(t), -std::numeric_limits<T>::infinity()));
        }
      }
  for (double end : { lo, hi })
    values.push_back(static_cast<T>(end));
  std::uniform_real_distribution<double> any(
    std::is_floating_point<T>::value ? -1e6 : lo, std::is_floating_point<T>::value ? 1e6 : hi);
  while (values.size() < 700)
    values.push_back(static_cast<T>(any(rng)));
  return values;
}

template <class T>
void expectBinsOfType(unsigned seed)
{
  const double lo = static_cast<double>(std::numeric_limits<T>::lowest());
  const double hi = static_cast<double>(std::numeric_limits<T>::max());
  std::mt19937 rng(seed);
  std::vector<std::vector<double>> sets;
  // 64 thresholds within the type's range, at integers and between them.
  std::vector<double> inside;
  std::uniform_real_distribution<double> within(std::max(lo, -1e5), std::min(hi, 1e5));
  for (int k = 0; k < 64; ++k)
    inside.push_back(k % 3 ? std::floor(within(rng)) : within(rng));
  sets.push_back(inside);
  // Beyond the type's ends (given thresholds may be anywhere): some below every value,
  // some above, 64 in between.
  std::vector<double> beyond = inside;
  for (double t : { lo - 1e9, lo - 0.5, hi + 0.5, hi + 3e9, 1e300, -1e300 })
    beyond.push_back(t);
  sets.push_back(beyond);
  // Few, and more than the vector search holds (65 in range): the other paths.
  sets.push_back({ std::floor((lo + hi) / 2) });
  std::vector<double> many = inside;
  many.push_back(std::min(hi - 1, 1e5 + 1));
  sets.push_back(many);
  for (auto& t : sets)
  {
    std::sort(t.begin(), t.end());
    t.erase(std::unique(t.begin(), t.end()), t.end());
    expectRowBinsCountThresholds(probeValues<T>(t, seed + 1), t);
  }
}

} // namespace

TEST(HistogramCdf, RowBinsCountTheThresholdsBelowEveryValue)
{
  expectBinsOfType<std::uint8_t>(1);
  expectBinsOfType<std::int8_t>(2);
  expectBinsOfType<std::int16_t>(3);
  expectBinsOfType<std::uint16_t>(4);
  expectBinsOfType<float>(5);
  expectBinsOfType<double>(6);
  // Thresholds between floats: each is above its nearest float or below it.
  std::vector<double> between;
  for (int k = 0; k < 64; ++k)
    between.push_back(0.1 * k + 1e-12 * (k % 2 ? 1 : -1));
  expectRowBinsCountThresholds(probeValues<float>(between, 7), between);
}

TEST(HistogramCdf, ReportsProgressEverySliceAndCancels)
{
  // A small volume has as few tiles as threads: progress goes by output slice, so that a
  // caller sees at least one report every 1/nz of the work from its own thread.
  const vao::Index3 dims = { 30, 28, 40 };
  auto v = randomVolume<std::int16_t>(dims, -1000, 1000, 61);
  const auto view = viewOf(v, dims);
  vao::AmbientOcclusionParameters p;
  p.method = vao::Method::HistogramCdf;
  p.radius = { 3, 3, 3 };
  ASSERT_TRUE(vao::volumeThresholds(view, 64, p.thresholds).ok);
  std::vector<float> out(view.voxelCount());
  std::vector<double> progress;
  vao::Execution execution;
  execution.threads = 1;
  execution.progress = [&](double fraction) { progress.push_back(fraction); };
  ASSERT_TRUE(vao::computeAmbientOcclusion(
    view, vao::Region::whole(view), p, { out.data(), nullptr }, execution)
                .ok);
  ASSERT_GE(progress.size(), static_cast<size_t>(dims[2]));
  EXPECT_TRUE(std::is_sorted(progress.begin(), progress.end()));
  double largestStep = progress.front();
  for (size_t i = 1; i < progress.size(); ++i)
    largestStep = std::max(largestStep, progress[i] - progress[i - 1]);
  EXPECT_LE(largestStep, 1.0 / dims[2] + 1e-12);
  EXPECT_DOUBLE_EQ(progress.back(), 1.0);
  execution.abortRequested = [] { return true; };
  const vao::Status status = vao::computeAmbientOcclusion(
    view, vao::Region::whole(view), p, { out.data(), nullptr }, execution);
  EXPECT_FALSE(status.ok);
  EXPECT_TRUE(status.aborted);
}
