// The shared (host/device) estimator formulas on hand-made neighbourhoods.
#include "vao/Estimators.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

namespace
{

using vao::ErfMode;
using vao::NeighbourhoodStats;

NeighbourhoodStats statsOf(const std::vector<double>& values)
{
  double sum = 0, sq = 0, lo = values[0], hi = values[0];
  for (double v : values)
  {
    sum += v;
    sq += v * v;
    lo = std::min(lo, v);
    hi = std::max(hi, v);
  }
  const double mean = sum / values.size();
  return { mean, std::max(0.0, sq / values.size() - mean * mean), lo, hi };
}

TEST(Estimators, WinitzkiIsCloseToErfAndOdd)
{
  double worst = 0;
  for (double x = -6; x <= 6; x += 0.001)
  {
    worst = std::max(worst, std::abs(vao::erfWinitzki(x) - std::erf(x)));
    ASSERT_DOUBLE_EQ(vao::erfWinitzki(-x), -vao::erfWinitzki(x));
  }
  EXPECT_LT(worst, 3.3e-4); // the documented bound of a = 8(pi - 3) / (3 pi (4 - pi))
  EXPECT_GT(worst, 3.2e-4) << "a different constant than docs/methods.md's";
  EXPECT_GT(worst, 1e-6); // it is an approximation, not erf itself
}

TEST(Estimators, GaussianCdfIsTheNormalCdf)
{
  const NeighbourhoodStats s{ 10.0, 4.0, 0.0, 20.0 };
  EXPECT_NEAR(vao::opennessGaussianCdf(10.0, s, ErfMode::Exact), 0.5, 1e-15);
  EXPECT_NEAR(vao::opennessGaussianCdf(12.0, s, ErfMode::Exact), 0.841344746068543, 1e-12);
  EXPECT_NEAR(vao::opennessGaussianCdf(6.0, s, ErfMode::Exact), 0.022750131948179, 1e-12);
  EXPECT_NEAR(vao::opennessGaussianCdf(12.0, s, ErfMode::Winitzki), 0.841344746068543, 2e-4);
}

TEST(Estimators, FlatNeighbourhoodGivesTheExactAnswerForEveryEstimator)
{
  const NeighbourhoodStats flat{ 500.0, 0.0, 500.0, 500.0 };
  for (auto method :
    { vao::Method::CdfReconstruction, vao::Method::GaussianCdf, vao::Method::Chebyshev })
    for (auto erf : { ErfMode::Exact, ErfMode::Winitzki })
    {
      EXPECT_EQ(vao::opennessFromStats(method, 500.0, flat, erf), 1.0);
      EXPECT_EQ(vao::opennessFromStats(method, 501.0, flat, erf), 1.0);
      EXPECT_EQ(vao::opennessFromStats(method, 499.0, flat, erf), 0.0);
    }
  // Rounding noise far below the threshold counts as flat too.
  const NeighbourhoodStats almost{ 1e6, 1e-5, 1e6, 1e6 };
  EXPECT_EQ(vao::opennessGaussianCdf(1e6 - 0.5, almost, ErfMode::Exact), 0.0);
}

TEST(Estimators, FlatRuleIgnoresTheRoundingOfTheMean)
{
  // One voxel (radius 0) of a float volume: vmin = vmax = q exactly, but the streamed sums
  // give a mean a few ulps away, on either side (seen on an H100: the GPU's and the CPU's
  // means straddled q). The answer must be 1 whichever side it lands. Double sums of a
  // float volume carry the rounding variance of values within about 1 of their shift.
  const double q = 0.7316485643386841; // a float32 value
  for (double mean : { q * (1 + 4e-16), q * (1 - 4e-16) })
  {
    const NeighbourhoodStats one{ mean, 3e-17, q, q, vao::sumRoundingVariance(1.0) };
    for (auto method :
      { vao::Method::CdfReconstruction, vao::Method::GaussianCdf, vao::Method::Chebyshev })
      for (auto erf : { ErfMode::Exact, ErfMode::Winitzki })
      {
        EXPECT_EQ(vao::opennessFromStats(method, q, one, erf), 1.0) << static_cast<int>(method);
        EXPECT_EQ(vao::opennessFromStats(method, q * (1 - 1e-6), one, erf), 0.0);
      }
  }
}

// The estimators depend on (q - mu) / sigma alone, so adding a constant to the data and the
// query, or scaling both, leaves the openness as it was. The flat rule must not break that:
// with a threshold of 1e-14 max(1, mu^2) the boxes below (sigma 3) were flat at an offset
// of 1e8 and in units of 2^-34, and the Gaussian CDF 0 or 1.
TEST(Estimators, OpennessIsTheSameAtAnyOffsetAndScale)
{
  const double sigma = 3.0;
  // Powers of two as scales, so that mu, sigma and q are exact at every offset.
  for (const double offset : { 0.0, 1e8, -1e12 })
    for (const double scale :
      { 1.0, std::ldexp(1.0, -34), std::ldexp(1.0, -100), std::ldexp(1.0, 66) })
    {
      const double mean = (1000.0 + offset) * scale, s = sigma * scale;
      const NeighbourhoodStats box{ mean, s * s, mean - 4.0 * s, mean + 4.0 * s };
      const double q = mean + 0.5 * s;
      EXPECT_NEAR(vao::opennessGaussianCdf(q, box, ErfMode::Exact), 0.6914624612740131, 1e-6)
        << offset << " " << scale;
      EXPECT_NEAR(vao::opennessChebyshev(q, box), 0.2, 1e-6) << offset << " " << scale;
    }
}

TEST(Estimators, ChebyshevIsExactForTwoValuedNeighbourhoodAtItsUpperValue)
{
  // Fraction p at the lower value a, 1 - p at the upper value b: Cantelli's bound on
  // P(v >= b) is exactly 1 - p, so the openness is p.
  for (int lower : { 1, 5, 13, 26 })
  {
    std::vector<double> values(lower, 100.0);
    values.resize(27, 350.0);
    const auto s = statsOf(values);
    EXPECT_NEAR(vao::opennessChebyshev(350.0, s), lower / 27.0, 1e-12);
  }
}

TEST(Estimators, ChebyshevBoundsTheExactFractionFromBelow)
{
  std::vector<double> values;
  for (int i = 0; i < 50; ++i)
    values.push_back(std::sin(i * 1.7) * 40 + i);
  const auto s = statsOf(values);
  for (double q : values)
  {
    double below = 0;
    for (double v : values)
      below += v <= q;
    EXPECT_LE(vao::opennessChebyshev(q, s), below / values.size() + 1e-12);
  }
}

TEST(Estimators, CdfReconstructionFollowsTheDefinition)
{
  const NeighbourhoodStats s{ 30.0, 100.0, 10.0, 70.0 };
  const double beta = (30.0 - 10.0) / (70.0 - 30.0);
  EXPECT_NEAR(vao::opennessCdfReconstruction(40.0, s), std::pow(0.5, beta), 1e-15);
  EXPECT_EQ(vao::opennessCdfReconstruction(70.0, s), 1.0);
  EXPECT_EQ(vao::opennessCdfReconstruction(90.0, s), 1.0);
  EXPECT_EQ(vao::opennessCdfReconstruction(5.0, s), 0.0);
  // A mean rounded past the maximum must not divide by zero or go negative.
  const NeighbourhoodStats rounded{ 70.0000001, 1.0, 10.0, 70.0 };
  EXPECT_EQ(vao::opennessCdfReconstruction(50.0, rounded), 0.0);
}

TEST(Estimators, EveryEstimatorStaysInTheUnitInterval)
{
  for (double mean : { -1000.0, 0.0, 3.0, 1e6 })
    for (double variance : { 0.0, 1e-3, 1.0, 1e4 })
      for (double q : { mean - 1e3, mean - 1.0, mean, mean + 0.5, mean + 1e4 })
      {
        const double sd = std::sqrt(variance);
        const NeighbourhoodStats s{ mean, variance, mean - 3 * sd, mean + 2 * sd };
        for (auto method :
          { vao::Method::CdfReconstruction, vao::Method::GaussianCdf, vao::Method::Chebyshev })
          for (auto erf : { ErfMode::Exact, ErfMode::Winitzki })
          {
            const double o = vao::opennessFromStats(method, q, s, erf);
            EXPECT_GE(o, 0.0);
            EXPECT_LE(o, 1.0);
          }
      }
}

TEST(Estimators, ClippedWindowCount)
{
  EXPECT_EQ(vao::clippedWindowCount(0, 3, 10), 4);
  EXPECT_EQ(vao::clippedWindowCount(5, 3, 10), 7);
  EXPECT_EQ(vao::clippedWindowCount(9, 3, 10), 4);
  EXPECT_EQ(vao::clippedWindowCount(2, 100, 5), 5);
  EXPECT_EQ(vao::clippedWindowCount(2, 0, 5), 1);
}

} // namespace
