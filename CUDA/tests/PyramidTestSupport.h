// Helpers of the variance occlusion map tests: a brute-force pyramid written from
// docs/methods.md (not from the kernel's code), test fields, and surface points.
#pragma once

#include "TestVolumes.h"
#include "vao/VarianceOcclusionMap.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <random>

namespace vaotest
{

using Vec3 = std::array<double, 3>;

// ---------------------------------------------------------------------------------------
// Brute-force reference: clipped, renormalised 5x5x5 Gaussian (sigma = 1 voxel) in double,
// evaluated everywhere, then decimation by 2.

struct RefLevel
{
  vao::Index3 dims;
  std::vector<double> m1, m2;
};

inline RefLevel refBlur(const RefLevel& in)
{
  const vao::Index3 d = in.dims;
  RefLevel out{ d, std::vector<double>(in.m1.size()), std::vector<double>(in.m1.size()) };
  for (std::int64_t z = 0; z < d[2]; ++z)
    for (std::int64_t y = 0; y < d[1]; ++y)
      for (std::int64_t x = 0; x < d[0]; ++x)
      {
        double s1 = 0, s2 = 0, sw = 0;
        for (int k = -2; k <= 2; ++k)
          for (int j = -2; j <= 2; ++j)
            for (int i = -2; i <= 2; ++i)
            {
              const std::int64_t X = x + i, Y = y + j, Z = z + k;
              if (X < 0 || Y < 0 || Z < 0 || X >= d[0] || Y >= d[1] || Z >= d[2])
                continue;
              const double w = std::exp(-0.5 * (i * i + j * j + k * k));
              const std::int64_t idx = (Z * d[1] + Y) * d[0] + X;
              s1 += w * in.m1[idx];
              s2 += w * in.m2[idx];
              sw += w;
            }
        const std::int64_t idx = (z * d[1] + y) * d[0] + x;
        out.m1[idx] = s1 / sw;
        out.m2[idx] = s2 / sw;
      }
  return out;
}

inline RefLevel refDecimate(const RefLevel& in)
{
  const vao::Index3 d = in.dims;
  const vao::Index3 m = { (d[0] + 1) / 2, (d[1] + 1) / 2, (d[2] + 1) / 2 };
  RefLevel out{ m, std::vector<double>(m[0] * m[1] * m[2]),
    std::vector<double>(m[0] * m[1] * m[2]) };
  for (std::int64_t z = 0; z < m[2]; ++z)
    for (std::int64_t y = 0; y < m[1]; ++y)
      for (std::int64_t x = 0; x < m[0]; ++x)
      {
        const std::int64_t o = (z * m[1] + y) * m[0] + x;
        const std::int64_t i = ((2 * z) * d[1] + 2 * y) * d[0] + 2 * x;
        out.m1[o] = in.m1[i];
        out.m2[o] = in.m2[i];
      }
  return out;
}

/// Levels of the reference pyramid; moments taken about `shift` (exact in double).
template <class T>
std::vector<RefLevel> refPyramid(
  const std::vector<T>& v, const vao::Index3& d, int levels, bool half, double shift)
{
  RefLevel raw{ d, std::vector<double>(v.size()), std::vector<double>(v.size()) };
  for (std::size_t i = 0; i < v.size(); ++i)
  {
    const double x = static_cast<double>(v[i]) - shift;
    raw.m1[i] = x;
    raw.m2[i] = x * x;
  }
  std::vector<RefLevel> out;
  RefLevel current = refBlur(raw);
  if (half)
    current = refDecimate(current);
  out.push_back(current);
  for (int l = 1; l < levels; ++l)
  {
    current = refDecimate(refBlur(current));
    out.push_back(current);
  }
  return out;
}

inline void expectLevelsMatch(const std::vector<vao::MomentLevel>& pyramid,
  const std::vector<RefLevel>& ref, double shift, double meanTol, double varTol, double varAbs)
{
  ASSERT_EQ(pyramid.size(), ref.size());
  for (std::size_t l = 0; l < ref.size(); ++l)
  {
    ASSERT_EQ(pyramid[l].dims, ref[l].dims) << "level " << l;
    for (std::size_t i = 0; i < ref[l].m1.size(); ++i)
    {
      const double mean = ref[l].m1[i] + shift;
      const double variance = std::max(0.0, ref[l].m2[i] - ref[l].m1[i] * ref[l].m1[i]);
      ASSERT_NEAR(pyramid[l].mean[i], mean, meanTol * std::max(1.0, std::fabs(mean)))
        << "level " << l << " voxel " << i;
      ASSERT_NEAR(pyramid[l].variance[i], variance, varTol * std::fabs(variance) + varAbs)
        << "level " << l << " voxel " << i;
    }
  }
}

// ---------------------------------------------------------------------------------------
// Scenes

struct Field
{
  vao::Index3 dims;
  Vec3 origin{ 0, 0, 0 };
  Vec3 spacing{ 1, 1, 1 };
  std::vector<float> values;
  vao::VolumeView view() const { return viewOf(values, dims); }
};

/// Occupancy-like density of a signed distance (negative inside): 1 inside, 0 outside,
/// linear across one voxel.
inline Field makeField(
  const vao::Index3& dims, const std::function<double(double, double, double)>& sdf)
{
  Field f{ dims, { 0, 0, 0 }, { 1, 1, 1 }, std::vector<float>(dims[0] * dims[1] * dims[2]) };
  for (std::int64_t z = 0; z < dims[2]; ++z)
    for (std::int64_t y = 0; y < dims[1]; ++y)
      for (std::int64_t x = 0; x < dims[0]; ++x)
        f.values[(z * dims[1] + y) * dims[0] + x] =
          static_cast<float>(std::min(1.0, std::max(0.0, 0.5 - sdf(x, y, z))));
  return f;
}

inline std::vector<vao::MomentLevel> pyramidOf(const Field& f, int levels = 4)
{
  std::vector<vao::MomentLevel> pyramid;
  vao::PyramidParameters p;
  p.levels = levels;
  const vao::Status s = vao::buildMomentPyramid(f.view(), f.origin, f.spacing, p, pyramid);
  EXPECT_TRUE(s.ok) << s.message;
  return pyramid;
}

inline std::vector<float> ao(const Field& f, const std::vector<vao::MomentLevel>& pyramid,
  const std::vector<double>& points, const std::vector<double>& normals,
  const vao::SurfaceOcclusionParameters& p = {})
{
  std::vector<float> out(points.size() / 3, -1.0f);
  const vao::Status s = vao::surfaceAmbientOcclusion(pyramid, f.view(), f.origin, f.spacing,
    points.data(), normals.data(), static_cast<std::int64_t>(out.size()), p, out.data());
  EXPECT_TRUE(s.ok) << s.message;
  return out;
}

/// Points on a sphere (Fibonacci lattice) and their outward normals.
inline void spherePoints(
  const Vec3& c, double r, int n, std::vector<double>& points, std::vector<double>& normals)
{
  const double golden = 3.14159265358979323846 * (3.0 - std::sqrt(5.0));
  for (int i = 0; i < n; ++i)
  {
    const double z = 1.0 - 2.0 * (i + 0.5) / n;
    const double rho = std::sqrt(1.0 - z * z);
    const Vec3 dir = { rho * std::cos(golden * i), rho * std::sin(golden * i), z };
    for (int a = 0; a < 3; ++a)
    {
      points.push_back(c[a] + r * dir[a]);
      normals.push_back(dir[a]);
    }
  }
}

/// A small level of `dims` voxels, anisotropic and off the origin, whose moments
/// moments(i, mean, variance) gives voxel by voxel, in order.
template <class Moments>
vao::MomentLevel smallLevel(const vao::Index3& dims, Moments&& moments)
{
  vao::MomentLevel level;
  level.dims = dims;
  level.origin = { 1.0, -2.0, 0.5 };
  level.spacing = { 1.5, 0.5, 2.0 };
  const auto n = static_cast<std::size_t>(dims[0] * dims[1] * dims[2]);
  level.mean.resize(n);
  level.variance.resize(n);
  for (std::size_t i = 0; i < n; ++i)
    moments(i, level.mean[i], level.variance[i]);
  return level;
}

/// f(p) for the surface query parameters of each estimator a level can feed (Chebyshev,
/// Gaussian CDF) with each query (half a voxel inside, the iso value 0.5).
template <class F>
void forEachSurfaceQuery(F&& f)
{
  for (vao::Method estimator : { vao::Method::Chebyshev, vao::Method::GaussianCdf })
    for (vao::SurfaceQuery query :
      { vao::SurfaceQuery::HalfVoxelInside, vao::SurfaceQuery::IsoValue })
    {
      vao::SurfaceOcclusionParameters p;
      p.estimator = estimator;
      p.query = query;
      p.isoValue = 0.5;
      f(p);
    }
}

inline double average(const std::vector<float>& v)
{
  double s = 0;
  for (float x : v)
    s += x;
  return s / v.size();
}

/// A sphere of radius 5.5 voxels about c inside a box shell (11 to 14 voxels from c):
/// the signed distance to the nearer, in voxel coordinates.
inline Field sphereInShell(const vao::Index3& d, const Vec3& c)
{
  return makeField(d,
    [&](double x, double y, double z)
    {
      const double sphere =
        std::sqrt((x - c[0]) * (x - c[0]) + (y - c[1]) * (y - c[1]) + (z - c[2]) * (z - c[2])) -
        5.5;
      const double m =
        std::max(std::fabs(x - c[0]), std::max(std::fabs(y - c[1]), std::fabs(z - c[2])));
      return std::min(sphere, std::max(11.0 - m, m - 14.0));
    });
}

/// sphereInShell on a grid that is no multiple of the tiles, off the origin, with unequal
/// spacings: the tiles at the far faces are partial.
inline Field shellScene(const vao::Index3& d)
{
  Field f = sphereInShell(d, { 0.47 * d[0], 0.52 * d[1], 0.5 * d[2] });
  f.origin = { -3.25, 1.5, 0.75 };
  f.spacing = { 0.8, 1.1, 0.95 };
  return f;
}

/// Surface points of the scene's sphere plus points anywhere in (and just outside) the
/// volume, with normals of every direction and length.
inline void scenePoints(const Field& f, std::vector<double>& points, std::vector<double>& normals)
{
  const Vec3 c = { f.origin[0] + 0.47 * f.dims[0] * f.spacing[0],
    f.origin[1] + 0.52 * f.dims[1] * f.spacing[1], f.origin[2] + 0.5 * f.dims[2] * f.spacing[2] };
  spherePoints(c, 5.5, 301, points, normals);
  std::mt19937 random(7);
  std::uniform_real_distribution<double> unit(-0.05, 1.05), direction(-1.0, 1.0);
  for (int i = 0; i < 150; ++i)
  {
    for (int a = 0; a < 3; ++a)
    {
      points.push_back(f.origin[a] + unit(random) * (f.dims[a] - 1) * f.spacing[a]);
      normals.push_back(direction(random) + (a == 2 ? 1e-3 : 0.0));
    }
  }
}

inline vao::SurfacePyramid surfacePyramidOf(const Field& f, const vao::PyramidParameters& p)
{
  vao::SurfacePyramid pyramid;
  const vao::Status s = vao::buildSurfacePyramid(f.view(), f.origin, f.spacing, p, pyramid);
  EXPECT_TRUE(s.ok) << s.message;
  return pyramid;
}

} // namespace vaotest
