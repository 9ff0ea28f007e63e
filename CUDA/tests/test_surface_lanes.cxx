// The surface queries' per-point query values in vector lanes (SurfaceLanes.h): the raw
// volume half a voxel inside (AO) and level 0's mean there (shadows), on each vector tier,
// against the scalar definitions (RawSampler.h, trilinearSample) and against a trilinear
// value written here from its definition. Also the ray bounds of the shadow march.
#include "cpu/moment_pyramid/RayBounds.h"
#include "cpu/moment_pyramid/SurfaceLanes.h"

#include "PyramidTestSupport.h"
#include "ReferenceFormulas.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
#include <vector>

namespace
{

using vaotest::Vec3;

/// rawLanes on each vector tier against RawSampler (the same bits: the same operations)
/// and against the reference trilinear (ReferenceFormulas.h), for a volume of T with `components`
/// values a voxel.
template <class T>
void checkRawLanes(T low, T high, int components)
{
  const vao::Index3 dims{ 7, 5, 4 };
  const Vec3 origin{ -1.0, 2.0, 0.25 }, spacing{ 0.5, 1.5, 3.0 };
  std::vector<T> values(static_cast<std::size_t>(components * dims[0] * dims[1] * dims[2]));
  std::mt19937_64 rng(static_cast<unsigned>(sizeof(T) * 10 + components));
  std::uniform_real_distribution<double> fraction(0.0, 1.0);
  const double lowest = static_cast<double>(low), span = static_cast<double>(high) - lowest;
  for (T& v : values) // the far ends of the type, and values between
    v = fraction(rng) < 0.2 ? (fraction(rng) < 0.5 ? low : high)
                            : static_cast<T>(lowest + fraction(rng) * span);
  vao::VolumeView view;
  view.data = values.data();
  view.dims = dims;
  view.voxelStride = components;
  const vao::detail::RawSampler<T> sampler(vao::detail::TypedVolume<T>(view), origin, spacing);
  ASSERT_TRUE(sampler.narrowIndices);
  std::uniform_real_distribution<double> where(-5.0, 15.0);
  constexpr int W = vao::detail::kLanes;
  for (int batch = 0; batch < 100; ++batch)
  {
    double x[W], y[W], z[W], vector[W];
    for (int k = 0; k < W; ++k)
    {
      x[k] = k == 0 ? origin[0] + (dims[0] - 1) * spacing[0] : where(rng); // on the last x face
      y[k] = k == 1 ? std::nan("") : where(rng);                           // NaN: the first voxel
      z[k] = k == 2 ? origin[2] : where(rng);
    }
    for (const vao::detail::SimdTier tier :
      { vao::detail::SimdTier::Avx2, vao::detail::SimdTier::Avx512 })
    {
      vao::detail::limitSimdTier(tier);
      vao::detail::rawLanes(sampler, x, y, z, vector);
      vao::detail::limitSimdTier(vao::detail::SimdTier::Avx512);
      for (int k = 0; k < W; ++k)
      {
        const double scalar = sampler({ x[k], y[k], z[k] });
        EXPECT_EQ(vector[k], scalar)
          << "lane " << k << ", tier " << static_cast<int>(tier) << ", " << sizeof(T) << " bytes";
        const Vec3 p{ x[k], std::isnan(y[k]) ? origin[1] : y[k], z[k] };
        const auto value = [&](std::int64_t i, std::int64_t j, std::int64_t l)
        {
          return static_cast<double>(
            values[static_cast<std::size_t>(components * ((l * dims[1] + j) * dims[0] + i))]);
        };
        const double reference = vaotest::reference::trilinear(dims, origin, spacing, p, value);
        EXPECT_NEAR(vector[k], reference, 1e-12 * std::max(1.0, static_cast<double>(high)))
          << "lane " << k;
      }
    }
  }
}

} // namespace

TEST(SurfaceLanes, RawQueryLanesEqualTheScalarSamplerForEveryType)
{
  for (const int components : { 1, 3 })
  {
    checkRawLanes<std::int8_t>(-128, 127, components);
    checkRawLanes<std::uint8_t>(0, 255, components);
    checkRawLanes<std::int16_t>(-32768, 32767, components);
    checkRawLanes<std::uint16_t>(0, 65535, components);
    checkRawLanes<std::int32_t>(std::numeric_limits<std::int32_t>::min(),
      std::numeric_limits<std::int32_t>::max(), components);
    checkRawLanes<std::uint32_t>(0, std::numeric_limits<std::uint32_t>::max(), components);
    checkRawLanes<std::int64_t>(-(std::int64_t(1) << 62), std::int64_t(1) << 62, components);
    checkRawLanes<std::uint64_t>(0, std::uint64_t(1) << 63, components);
    checkRawLanes<float>(-3e38f, 3e38f, components);
    checkRawLanes<double>(-1e300, 1e300, components);
  }
}

TEST(SurfaceLanes, MeanLanesEqualTheTrilinearSample)
{
  for (const vao::Index3 dims : { vao::Index3{ 9, 7, 5 }, vao::Index3{ 1, 5, 3 } })
  {
    vao::MomentLevel level;
    level.dims = dims;
    level.origin = { 1.0, -2.0, 0.5 };
    level.spacing = { 1.5, 0.5, 2.0 };
    const auto n = static_cast<std::size_t>(dims[0] * dims[1] * dims[2]);
    std::mt19937 rng(7);
    std::uniform_real_distribution<double> value(-50.0, 50.0), where(-4.0, 16.0);
    level.mean.resize(n);
    level.variance.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      level.mean[i] = static_cast<float>(value(rng));
    const vao::detail::LevelGrid grid(level);
    constexpr int W = vao::detail::kLanes;
    for (int batch = 0; batch < 100; ++batch)
    {
      double x[W], y[W], z[W], vector[W];
      for (int k = 0; k < W; ++k)
      {
        x[k] = where(rng);
        y[k] = where(rng);
        z[k] = where(rng);
      }
      for (const vao::detail::SimdTier tier :
        { vao::detail::SimdTier::Avx2, vao::detail::SimdTier::Avx512 })
      {
        vao::detail::limitSimdTier(tier);
        vao::detail::meanLanes(grid, x, y, z, vector);
        vao::detail::limitSimdTier(vao::detail::SimdTier::Avx512);
        for (int k = 0; k < W; ++k)
        {
          const auto mean = [&](std::int64_t i, std::int64_t j, std::int64_t l)
          {
            return static_cast<double>(
              level.mean[static_cast<std::size_t>((l * dims[1] + j) * dims[0] + i)]);
          };
          const double reference = vaotest::reference::trilinear(
            dims, level.origin, level.spacing, Vec3{ x[k], y[k], z[k] }, mean);
          EXPECT_NEAR(vector[k], reference, 1e-12)
            << "lane " << k << ", tier " << static_cast<int>(tier);
        }
      }
    }
  }
}

TEST(SurfaceLanes, RayBoundsHoldEveryCellBoundAheadOnTheRay)
{
  // Levels with one-voxel axes, unpaired x rows, anisotropic spacing; lights along the
  // axes, the diagonals and at random; steps shorter and longer than a cell.
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> value(-50.0, 50.0), unit(0.0, 1.0), direction(-1.0, 1.0);
  int checked = 0;
  for (const vao::Index3 dims :
    { vao::Index3{ 9, 7, 5 }, vao::Index3{ 1, 6, 4 }, vao::Index3{ 8, 1, 1 } })
  {
    const vao::MomentLevel level = vaotest::smallLevel(dims,
      [&](std::size_t, float& mean, float& variance)
      {
        mean = static_cast<float>(value(rng));
        variance = static_cast<float>(std::fabs(value(rng)));
      });
    vao::detail::LevelGrid grid(level);
    const vao::detail::CellBounds cells(level, grid);
    for (int trial = 0; trial < 60; ++trial)
    {
      Vec3 light = { direction(rng), direction(rng), direction(rng) };
      if (trial < 6) // along an axis, either way
        light = { trial / 2 == 0 ? 1.0 : 0.0, trial / 2 == 1 ? 1.0 : 0.0,
          trial / 2 == 2 ? 1.0 : 0.0 };
      if (trial < 6 && trial % 2)
        light = { -light[0], -light[1], -light[2] };
      const double length =
        std::sqrt(light[0] * light[0] + light[1] * light[1] + light[2] * light[2]);
      for (double& c : light)
        c /= length;
      const double step = trial % 3 == 0 ? 0.3 : trial % 3 == 1 ? 1.7 : 4.5;
      const vao::detail::RayBounds rays(grid, step, light);
      for (int start = 0; start < 40; ++start)
      {
        // A start anywhere around the level, and the steps of a march from it.
        Vec3 from;
        for (int a = 0; a < 3; ++a)
          from[a] = level.origin[a] + (unit(rng) * 1.4 - 0.2) * dims[a] * level.spacing[a];
        // The cell of a world position: its lower corner, clamped (the last x voxel is the
        // upper corner of the cell below it where a row has two or more).
        const auto cellOf = [&](const Vec3& p)
        {
          std::int64_t c[3];
          for (int a = 0; a < 3; ++a)
          {
            const double u =
              std::clamp((p[a] - level.origin[a]) / level.spacing[a], 0.0, dims[a] - 1.0);
            c[a] = static_cast<std::int64_t>(std::floor(u));
          }
          if (dims[0] >= 2)
            c[0] = std::min<std::int64_t>(c[0], dims[0] - 2);
          return (c[2] * dims[1] + c[1]) * dims[0] + c[0];
        };
        const std::int64_t first = cellOf(from);
        double t = 0.0;
        for (int k = 0; k < 30; ++k, t += step)
        {
          const Vec3 at = { from[0] + t * light[0], from[1] + t * light[1],
            from[2] + t * light[2] };
          const std::int64_t c = cellOf(at);
          EXPECT_LE(grid.cellBounds[2 * c], rays.data()[2 * first])
            << "trial " << trial << ", step " << k;
          EXPECT_LE(grid.cellBounds[2 * c + 1], rays.data()[2 * first + 1])
            << "trial " << trial << ", step " << k;
          ++checked;
        }
      }
    }
  }
  EXPECT_EQ(checked, 3 * 60 * 40 * 30);
}
