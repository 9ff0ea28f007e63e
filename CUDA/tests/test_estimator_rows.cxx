// The estimators over rows of neighbourhoods (EstimatorRows.h, four voxels at a time on
// AVX2 and eight on AVX-512, with glibc's vector erf, exp and log and AVX-512's piecewise erf;
// each tier the processor has) against the formulas of docs/methods.md written out again
// (ReferenceFormulas.h): rows of every length around the vector width, queries per voxel
// and one iso value, flat boxes among noisy ones, small and large magnitudes.
#include "ReferenceFormulas.h"
#include "cpu/box_statistics/EstimatorRows.h"
#include "cpu/box_statistics/MomentRows.h"
#include "cpu/simd/CpuDispatch.h"
#include "cpu/simd/DoubleLanes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <limits>
#include <random>
#include <vector>

namespace
{

/// The error of erf's few ulps near +-1, halved in the openness (1 + erf) / 2.
constexpr double kHalfUlpOfOne = 1.1102230246251565e-16;

/// Above this openness a float differing from the scalar formula's is a coincidence of
/// rounding; below it, where 1 + erf cancels, the erf's last bits show in most floats.
constexpr double kTail = 1e-6;

struct RowData
{
  std::vector<double> value, count, mean, variance, minimum, maximum, query;
  double roundingVariance = 0.0;

  vao::detail::NeighbourhoodRow row() const
  {
    vao::detail::NeighbourhoodRow r;
    r.size = static_cast<std::int64_t>(this->mean.size());
    r.roundingVariance = this->roundingVariance;
    r.value = this->value.data();
    r.count = this->count.data();
    r.mean = this->mean.data();
    r.variance = this->variance.data();
    r.minimum = this->minimum.data();
    r.maximum = this->maximum.data();
    return r;
  }
};

/// n neighbourhoods around `magnitude`: a quarter flat (variance 0 or within the rounding
/// that double sums of values within `magnitude` of their shift allow, 1e-12 magnitude^2),
/// the rest with spreads from 1e-3 to 10 times the magnitude; queries up to `reach`
/// standard deviations either side, or exactly the mean of a flat box.
RowData makeRow(std::size_t n, double magnitude, std::mt19937& rng, double reach = 4.0)
{
  std::uniform_real_distribution<double> unit(-1.0, 1.0);
  RowData d;
  d.roundingVariance = 1e-12 * magnitude * magnitude;
  for (std::size_t i = 0; i < n; ++i)
  {
    const double mean = magnitude * unit(rng);
    const bool flat = rng() % 4 == 0;
    const double sd = flat ? 0.0 : magnitude * std::pow(10.0, 2.0 * unit(rng) - 1.0);
    const double variance =
      flat ? (rng() % 2 ? 0.0 : d.roundingVariance * (0.5 + 0.5 * unit(rng))) : sd * sd;
    double q = mean + reach * sd * unit(rng);
    if (flat)
      q = rng() % 3 == 0 ? mean : mean + magnitude * unit(rng);
    d.mean.push_back(mean);
    d.variance.push_back(variance);
    // CDF Reconstruction's other end: the mean at the maximum (beta infinite), as rounding
    // can put it; at the minimum it needs a flat box.
    d.minimum.push_back(flat ? mean : mean - 3.0 * sd);
    d.maximum.push_back(flat || rng() % 8 == 0 ? mean : mean + 3.0 * sd);
    d.value.push_back(q);
    d.count.push_back(27.0);
    d.query.push_back(q);
  }
  return d;
}

double referenceOpenness(vao::Method method, double q, const RowData& d, std::size_t i)
{
  const vaotest::reference::Statistics s{ d.mean[i], d.variance[i], d.minimum[i], d.maximum[i],
    d.roundingVariance };
  switch (method)
  {
    case vao::Method::Chebyshev:
      return vaotest::reference::chebyshev(q, s);
    case vao::Method::CdfReconstruction:
      return vaotest::reference::cdfReconstruction(q, s);
    default:
      return vaotest::reference::gaussianCdf(q, s, false);
  }
}

/// Runs check() with the row loops capped at each tier (all tiers this processor lacks run
/// as its best one), then lifts the cap.
template <class Check>
void onEveryTier(Check&& check)
{
  using vao::detail::SimdTier;
  for (const SimdTier tier : { SimdTier::Baseline, SimdTier::Avx2, SimdTier::Avx512 })
  {
    SCOPED_TRACE(static_cast<int>(tier));
    vao::detail::limitSimdTier(tier);
    check();
  }
  vao::detail::limitSimdTier(SimdTier::Avx512);
}

} // namespace

TEST(EstimatorRows, EveryLengthQueryAndMagnitudeAgainstTheReference)
{
  onEveryTier(
    []
    {
      std::mt19937 rng(20261202);
      std::size_t compared = 0, offByOneUlp = 0;
      for (const vao::Method method :
        { vao::Method::GaussianCdf, vao::Method::Chebyshev, vao::Method::CdfReconstruction })
      {
        // Reach 12: most Gaussian CDF lanes beyond |z| = 6, where erf is +-1, often whole groups.
        for (const double magnitude : { 1.0, 1000.0, 3.0e6, -12.0 })
        {
          for (std::size_t n = 0; n <= 37; ++n)
          {
            const RowData d =
              magnitude > 0 ? makeRow(n, magnitude, rng) : makeRow(n, 1000.0, rng, -magnitude);
            const double iso = magnitude * 0.25;
            for (const bool perVoxel : { true, false })
            {
              std::vector<float> out(n, -1.0f);
              vao::detail::opennessRow(method, vao::ErfMode::Exact, d.row(),
                perVoxel ? d.query.data() : nullptr, iso, out.data());
              for (std::size_t i = 0; i < n; ++i)
              {
                const double q = perVoxel ? d.query[i] : iso;
                const float expected = static_cast<float>(referenceOpenness(method, q, d, i));
                ++compared;
                if (out[i] == expected)
                  continue;
                // The vector erf and pow are within a few double ulps of the scalar ones: the
                // float may round the other way (one float ulp), or, in the tails where 1 + erf
                // cancels, differ by those few ulps of 1, as the scalar value differs from the
                // truth.
                ASSERT_NE(method, vao::Method::Chebyshev)
                  << "voxel " << i << " of " << n << ": " << out[i] << " vs " << expected;
                const double tolerance = std::fmax(
                  std::fabs(std::nextafter(expected, out[i]) - expected), 8 * kHalfUlpOfOne);
                ASSERT_LE(std::fabs(double(out[i]) - expected), tolerance)
                  << "voxel " << i << " of " << n << ", q " << q << ", mean " << d.mean[i]
                  << ", variance " << d.variance[i];
                offByOneUlp += expected > kTail; // a rounding coincidence there
              }
            }
          }
        }
      }
      std::printf("%zu opennesses compared, %zu above the tail a rounding away from the reference, "
                  "vector form: %s\n",
        compared, offByOneUlp,
        vao::detail::opennessRowIsVector(vao::Method::GaussianCdf, vao::ErfMode::Exact) ? "yes"
                                                                                        : "no");
      EXPECT_LE(offByOneUlp * 1000, compared); // a rounding coincidence, not a habit
    });
}

TEST(EstimatorRows, VectorAndPlainFormsAgree)
{
  std::mt19937 rng(7);
  RowData d = makeRow(2048, 500.0, rng);
  const RowData far = makeRow(2051, 500.0, rng, 12.0); // erf at +-1, whole groups
  using Field = std::vector<double> RowData::*;
  for (const Field field : { &RowData::value, &RowData::count, &RowData::mean, &RowData::variance,
         &RowData::minimum, &RowData::maximum, &RowData::query })
    (d.*field).insert((d.*field).end(), (far.*field).begin(), (far.*field).end());
  onEveryTier(
    [&]
    {
      for (const vao::Method method :
        { vao::Method::GaussianCdf, vao::Method::Chebyshev, vao::Method::CdfReconstruction })
      {
        std::vector<float> fast(d.mean.size()), plain(d.mean.size());
        vao::detail::opennessRow(
          method, vao::ErfMode::Exact, d.row(), d.query.data(), 0.0, fast.data());
        vao::detail::opennessRowPlain(
          method, vao::ErfMode::Exact, d.row(), d.query.data(), 0.0, plain.data());
        std::size_t differ = 0;
        for (std::size_t i = 0; i < fast.size(); ++i)
        {
          if (fast[i] != plain[i])
          {
            ASSERT_NE(method, vao::Method::Chebyshev)
              << "Chebyshev rounds as the scalar formula, voxel " << i;
            const double tolerance =
              std::fmax(std::fabs(std::nextafter(plain[i], fast[i]) - plain[i]), 8 * kHalfUlpOfOne);
            ASSERT_LE(std::fabs(double(fast[i]) - plain[i]), tolerance) << "voxel " << i;
            differ += plain[i] > kTail;
          }
        }
        EXPECT_LE(differ * 1000, fast.size());
      }
    });
}

// Chebyshev and the Gaussian CDF straight from exact integer sums (opennessFromExactSums,
// on the row's lanes and on the plain loop) against the reference formulas given the mean
// and variance of the same boxes: boxes of two int16 values, flat ones among them, sums
// the lanes take in doubles and sums too large for that, mixed within a row; queries at
// either value, between, just outside, an iso value and iso values far beyond the data.
TEST(EstimatorRows, ExactSumsAgainstTheReference)
{
  onEveryTier(
    []
    {
      std::mt19937_64 rng(20261203);
      std::size_t compared = 0, offByOneUlp = 0;
      for (const vao::Method method : { vao::Method::Chebyshev, vao::Method::GaussianCdf })
      {
        for (std::int64_t n = 0; n <= 37; ++n)
        {
          for (const std::int64_t countYZ : { std::int64_t(1), std::int64_t(441) })
          {
            std::vector<std::int64_t> sum(n), sumSquares(n), countX(n);
            std::vector<double> query(n);
            std::vector<vaotest::reference::Statistics> stats(n);
            for (std::int64_t i = 0; i < n; ++i)
            {
              countX[i] = 1 + static_cast<std::int64_t>(rng() % 21);
              const std::int64_t c = countX[i] * countYZ;
              const std::int64_t magnitude = rng() % 3 == 0 ? 32768 : 3000;
              const std::int64_t a = static_cast<std::int64_t>(rng() % (2 * magnitude)) - magnitude;
              const std::int64_t b = static_cast<std::int64_t>(rng() % (2 * magnitude)) - magnitude;
              const std::int64_t choice = static_cast<std::int64_t>(rng() % 6);
              const std::int64_t ofA =
                choice == 0 ? c : (choice == 1 ? 0 : static_cast<std::int64_t>(rng() % (c + 1)));
              sum[i] = a * ofA + b * (c - ofA);
              sumSquares[i] = a * a * ofA + b * b * (c - ofA);
              const std::int64_t queries[] = { a, b, (a + b) / 2, a - 1, b + 1 };
              query[i] = static_cast<double>(queries[rng() % 5]);
              const __int128 numerator =
                static_cast<__int128>(c) * sumSquares[i] - static_cast<__int128>(sum[i]) * sum[i];
              const double cd = static_cast<double>(c);
              const double lowest =
                static_cast<double>(ofA == 0 ? b : (ofA == c ? a : std::min(a, b)));
              const double highest =
                static_cast<double>(ofA == 0 ? b : (ofA == c ? a : std::max(a, b)));
              stats[i] = { static_cast<double>(sum[i]) / cd,
                numerator > 0 ? static_cast<double>(numerator) / (cd * cd) : 0.0, lowest, highest };
            }
            vao::detail::NeighbourhoodRow row;
            row.size = n;
            row.sum = sum.data();
            row.sumSquares = sumSquares.data();
            row.countX = countX.data();
            row.countYZ = countYZ;
            for (const double iso : { 750.5, 1e300, -1e300 }) // iso values whose q c overflows too
              for (const bool perVoxel : { true, false })
              {
                std::vector<float> out(n, -1.0f);
                vao::detail::opennessRow(method, vao::ErfMode::Exact, row,
                  perVoxel ? query.data() : nullptr, iso, out.data());
                for (std::int64_t i = 0; i < n; ++i)
                {
                  const double q = perVoxel ? query[i] : iso;
                  const double reference = method == vao::Method::Chebyshev
                    ? vaotest::reference::chebyshev(q, stats[i])
                    : vaotest::reference::gaussianCdf(q, stats[i], false);
                  const float expected = static_cast<float>(reference);
                  ++compared;
                  if (out[i] == expected)
                    continue;
                  // The sums' form rounds differently from the mean and variance's (a double
                  // ulp or two), and the vector erf is within a few ulps of the scalar one.
                  const double tolerance = std::fmax(
                    std::fabs(std::nextafter(expected, out[i]) - expected), 8 * kHalfUlpOfOne);
                  ASSERT_LE(std::fabs(double(out[i]) - expected), tolerance)
                    << "box " << i << " of " << n << ", q " << q << ", mean " << stats[i].mean
                    << ", variance " << stats[i].variance;
                  offByOneUlp += expected > kTail;
                }
              }
          }
        }
      }
      std::printf("%zu opennesses from exact sums compared, %zu above the tail a rounding away "
                  "from the reference\n",
        compared, offByOneUlp);
      EXPECT_LE(offByOneUlp * 1000, compared);
    });
}

#if VAO_HAVE_AVX2_TARGET
/// AVX-512's erf (DoubleLanes.h: 16 polynomial pieces) on n values, padded to whole vectors.
VAO_AVX512_INLINE std::vector<double> erfOnAvx512(std::vector<double> x)
{
  x.resize((x.size() + 7) / 8 * 8, 0.0);
  std::vector<double> out(x.size());
  for (std::size_t i = 0; i < x.size(); i += 8)
    vao::detail::avx512::store(
      out.data() + i, vao::detail::avx512::erf(vao::detail::avx512::load(x.data() + i)));
  return out;
}

// The piecewise erf against glibc's scalar erf (within an ulp): within 2^-52 absolute on a
// fine grid over [-7, 7], at and beside every piece's ends, near 0 and 6, and within 2^-50
// relative on the first piece (|x| < 3/8, down to subnormals); odd; +-1 at
// +-infinity and NaN kept.
TEST(EstimatorRows, PiecewiseErfOfAvx512WithinTwoToTheMinus52OfErf)
{
  if (vao::detail::cpuSimdTier() < vao::detail::SimdTier::Avx512)
    GTEST_SKIP() << "no AVX-512: glibc's vector erf runs on AVX2";
  std::vector<double> x;
  for (int i = -7 * 8192; i <= 7 * 8192; ++i)
    x.push_back(i / 8192.0 + 1e-6 * std::sin(i)); // off the grid of the pieces' ends too
  using vao::detail::kErfPieceWidth;
  const double top = vao::detail::kErfTop;
  for (int k = 0; k <= vao::detail::kErfPieces + 1; ++k)
  {
    const double end = kErfPieceWidth * k; // where the pieces meet
    for (const double e : { end, std::nextafter(end, 0.0), std::nextafter(end, 10.0) })
      x.insert(x.end(), { e, -e });
  }
  for (const double e : { top - 1e-7, top + 1e-7, 1e-300, 4.9e-324, 1e300, -1e300, -0.0 })
    x.push_back(e);
  const std::size_t finite = x.size();
  const double inf = std::numeric_limits<double>::infinity();
  x.insert(x.end(), { inf, -inf, std::numeric_limits<double>::quiet_NaN() });
  const std::vector<double> y = erfOnAvx512(x);
  double worst = 0.0, worstRelative = 0.0;
  for (std::size_t i = 0; i < finite; ++i)
  {
    const double error = std::fabs(y[i] - std::erf(x[i]));
    worst = std::fmax(worst, error);
    ASSERT_LE(error, 2.220446049250313e-16)
      << "x " << x[i] << ": " << y[i] << " against " << std::erf(x[i]);
    ASSERT_LE(std::fabs(y[i]), 1.0) << "x " << x[i];
    if (std::fabs(x[i]) < kErfPieceWidth && x[i] != 0.0) // the first piece: relative accuracy too
    {
      worstRelative = std::fmax(worstRelative, error / std::fabs(std::erf(x[i])));
      ASSERT_LE(error, std::ldexp(1.0, -50) * std::fabs(std::erf(x[i]))) << "x " << x[i];
    }
  }
  for (std::size_t i = 0; i + 1 < finite; ++i) // odd: the pieces fit |x|, the sign comes back
    if (x[i + 1] == -x[i])
      ASSERT_EQ(y[i + 1], -y[i]) << "x " << x[i];
  EXPECT_EQ(y[finite], 1.0);
  EXPECT_EQ(y[finite + 1], -1.0);
  EXPECT_TRUE(std::isnan(y[finite + 2]));
  std::printf("%zu values: within %.3g of glibc's erf (%.3g relative below 0.375)\n", finite, worst,
    worstRelative);
}
#endif

// The mean and variance of rows of boxes from exact sums: against the definition (double of
// the exact integer numerator count * sum(v^2) - sum(v)^2, over count^2), bit for bit, for
// sums that the vector form takes in doubles and sums too large for that (the int16 range
// in large boxes), mixed within a row.
TEST(MomentRows, MeanAndVarianceFromExactSumsBitForBit)
{
  onEveryTier(
    []
    {
      std::mt19937_64 rng(99);
      for (std::int64_t n = 0; n <= 29; ++n)
      {
        for (const std::int64_t countYZ :
          { std::int64_t(1), std::int64_t(441), std::int64_t(1) << 20 })
        {
          std::vector<std::int64_t> sum(n), sumSquares(n), countX(n);
          for (std::int64_t i = 0; i < n; ++i)
          {
            countX[i] = 1 + static_cast<std::int64_t>(rng() % 21);
            const std::int64_t count = countX[i] * countYZ;
            const std::int64_t magnitude =
              rng() % 3 == 0 ? 32768 : 3000; // the int16 range, or a CT's
            // Values of the box: a few distinct ones stand for all (only the sums matter).
            const std::int64_t a = static_cast<std::int64_t>(rng() % (2 * magnitude)) - magnitude;
            const std::int64_t b = static_cast<std::int64_t>(rng() % (2 * magnitude)) - magnitude;
            const std::int64_t ofA = static_cast<std::int64_t>(rng() % (count + 1));
            sum[i] = a * ofA + b * (count - ofA);
            sumSquares[i] = a * a * ofA + b * b * (count - ofA);
          }
          std::vector<double> count(n), mean(n), variance(n);
          vao::detail::meanVarianceRowExact(sum.data(), sumSquares.data(), countX.data(), countYZ,
            n, count.data(), mean.data(), variance.data());
          for (std::int64_t i = 0; i < n; ++i)
          {
            const std::int64_t c = countX[i] * countYZ;
            const __int128 numerator =
              static_cast<__int128>(c) * sumSquares[i] - static_cast<__int128>(sum[i]) * sum[i];
            const double cd = static_cast<double>(c);
            ASSERT_EQ(count[i], cd);
            ASSERT_EQ(mean[i], static_cast<double>(sum[i]) / cd) << "box " << i << " of " << n;
            ASSERT_EQ(variance[i], numerator > 0 ? static_cast<double>(numerator) / (cd * cd) : 0.0)
              << "box " << i << " of " << n << ", count " << c;
          }
        }
      }
    });
}
