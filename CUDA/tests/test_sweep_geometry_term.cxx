// Occlusion sweeping: the closed-form geometry term G_s(N) of Eq. 5 against quadrature.
#include "SweepTestSupport.h"

#include <gtest/gtest.h>

#include <functional>
#include <map>

using namespace vaotest;

namespace
{

constexpr double kPi = 3.14159265358979323846;

// ---------------------------------------------------------------------------------------
// Geometry term (Eq. 5)

std::array<double, 3> randomUnit(std::mt19937_64& rng)
{
  std::normal_distribution<double> normal;
  std::array<double, 3> n{ normal(rng), normal(rng), normal(rng) };
  const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (double& c : n)
    c /= length;
  return n;
}

/// Midpoint quadrature of max(N.w, 0) (or |N.w|) over octant s in (theta, phi), with the
/// direction grid shared by all calls.
double quadrature(int s, const std::array<double, 3>& n, bool twoSided)
{
  constexpr int K = 1200;
  static const std::vector<std::array<double, 4>> grid = []
  {
    std::vector<std::array<double, 4>> g;
    const double step = 0.5 * kPi / K;
    for (int i = 0; i < K; ++i)
      for (int j = 0; j < K; ++j)
      {
        const double theta = (i + 0.5) * step, phi = (j + 0.5) * step;
        g.push_back({ std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
          std::cos(theta), std::sin(theta) * step * step });
      }
    return g;
  }();
  const auto dir = vao::sweepDirection(s);
  const double m[3] = { -dir[0] * n[0], -dir[1] * n[1],
    -dir[2] * n[2] }; // octant s: sign(w) = -dir
  double sum = 0;
  for (const auto& w : grid)
  {
    const double dot = m[0] * w[0] + m[1] * w[1] + m[2] * w[2];
    sum += (twoSided ? std::abs(dot) : std::max(dot, 0.0)) * w[3];
  }
  return sum;
}

TEST(GeometryTerm, OctantsSumToPiForEveryNormal)
{
  std::mt19937_64 rng(11);
  for (int k = 0; k < 5000; ++k)
  {
    const auto n = randomUnit(rng);
    double one = 0, two = 0;
    for (int s = 0; s < 8; ++s)
    {
      const double g = vao::geometryTerm(s, n);
      EXPECT_GE(g, 0.0);
      one += g;
      two += vao::geometryTerm(s, n, true);
      const std::array<double, 3> flipped{ -n[0], -n[1], -n[2] };
      EXPECT_NEAR(vao::geometryTerm(s, n, true), g + vao::geometryTerm(s, flipped), 1e-12);
    }
    ASSERT_NEAR(one, kPi, 1e-9);
    ASSERT_NEAR(two, 2 * kPi, 1e-9);
  }
}

TEST(GeometryTerm, MatchesQuadrature)
{
  std::vector<std::array<double, 3>> normals = { { 0, 0, 1 }, { 1, 0, 0 }, { 0, -1, 0 },
    { 1, 1, 1 }, { 1, -1, 0 }, { 0.2, 0.1, -0.97 }, { 1e-9, 1, 1e-7 }, { -0.7, 0.7, 0.14 } };
  std::mt19937_64 rng(5);
  for (int k = 0; k < 8; ++k)
    normals.push_back(randomUnit(rng));
  for (const auto& raw : normals)
  {
    const double length = std::sqrt(raw[0] * raw[0] + raw[1] * raw[1] + raw[2] * raw[2]);
    const std::array<double, 3> n{ raw[0] / length, raw[1] / length, raw[2] / length };
    for (int s = 0; s < 8; ++s)
      for (bool twoSided : { false, true })
      {
        EXPECT_NEAR(vao::geometryTerm(s, raw, twoSided), quadrature(s, n, twoSided), 1e-4)
          << "octant " << s << " N = (" << n[0] << ", " << n[1] << ", " << n[2] << ")";
      }
  }
}

TEST(GeometryTerm, UpwardNormalSeesTheUpperOctants)
{
  // Octant s holds the directions opposite to its sweep: s = 4..7 sweep down (dir z = -1)
  // and so carry the light from above.
  for (int s = 0; s < 8; ++s)
  {
    EXPECT_NEAR(vao::geometryTerm(s, { 0, 0, 1 }), s >= 4 ? kPi / 4 : 0.0, 1e-12) << s;
    EXPECT_NEAR(vao::geometryTerm(s, { 0, 0, 2.5 }), s >= 4 ? kPi / 4 : 0.0, 1e-12) << s;
    EXPECT_NEAR(vao::geometryTerm(s, { 0, 0, 1 }, true), kPi / 4, 1e-12) << s;
  }
  EXPECT_EQ(vao::sweepDirection(0), (std::array<int, 3>{ 1, 1, 1 }));
  EXPECT_EQ(vao::sweepDirection(1), (std::array<int, 3>{ -1, 1, 1 }));
  EXPECT_EQ(vao::sweepDirection(6), (std::array<int, 3>{ 1, -1, -1 }));
}

} // namespace
