// Exact Rays against a ray caster written here from docs/methods.md section 11: its own
// Fibonacci directions, world positions turned into index coordinates through the inverse
// of the image's frame, its own trilinear interpolation and piecewise-linear opacity, long
// double sums. Then what holds whatever the code: an empty function is open, a uniform
// medium transmits (1 - alpha)^(R / u), a piece grown by rayReach gives the whole volume's
// result, and bad rays are refused.
#include "TestVolumes.h"

#include "vao/AmbientOcclusion.h"
#include "vao/RayCasting.h"
#include "vao/Validation.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

namespace
{

using Matrix = std::array<double, 9>; // row-major

/// Straight lines between the nodes, the end opacities outside them (clamping).
double rampOpacity(const vao::OpacityFunction& f, double v)
{
  const auto& n = f.nodes;
  if (v <= n.front().x)
    return n.front().y;
  if (v >= n.back().x)
    return n.back().y;
  std::size_t k = 0;
  while (v > n[k + 1].x)
    ++k;
  return n[k].y + (v - n[k].x) / (n[k + 1].x - n[k].x) * (n[k + 1].y - n[k].y);
}

struct Scene
{
  vao::Index3 dims;
  std::vector<float> values;
  std::array<double, 3> origin; // world position of voxel (0, 0, 0)
  std::array<double, 3> spacing;
  Matrix direction;
  vao::OpacityFunction opacity;
  double radius; // world
  double unit;   // opacity unit distance
  int rays;
};

/// The value at index coordinates (i, j, k), or NaN outside the grid.
long double valueAt(const Scene& s, long double i, long double j, long double k)
{
  const long double c[3] = { i, j, k };
  std::int64_t lo[3];
  long double w[3];
  for (int a = 0; a < 3; ++a)
  {
    if (c[a] < 0 || c[a] > s.dims[a] - 1)
      return NAN;
    lo[a] = static_cast<std::int64_t>(std::floor(c[a]));
    if (lo[a] == s.dims[a] - 1 && s.dims[a] > 1)
      --lo[a];
    w[a] = c[a] - lo[a];
  }
  long double sum = 0;
  for (int corner = 0; corner < 8; ++corner)
  {
    long double weight = 1;
    std::int64_t at[3];
    for (int a = 0; a < 3; ++a)
    {
      const int up = (corner >> a) & 1;
      weight *= up ? w[a] : 1 - w[a];
      at[a] = std::min(lo[a] + up, s.dims[a] - 1);
    }
    if (weight != 0)
      sum += weight *
        s.values[static_cast<std::size_t>((at[2] * s.dims[1] + at[1]) * s.dims[0] + at[0])];
  }
  return sum;
}

/// AO_ray of voxel (x, y, z) by the definition.
double referenceAo(const Scene& s, std::int64_t x, std::int64_t y, std::int64_t z)
{
  const long double pi = 3.141592653589793238462643383279L;
  const double smallest = std::min({ s.spacing[0], s.spacing[1], s.spacing[2] });
  const std::int64_t m = static_cast<std::int64_t>(std::ceil(s.radius / (smallest / 2)));
  const long double dt = s.radius / static_cast<long double>(m);
  const Matrix& d = s.direction;
  // The voxel's world position: origin + D diag(h) index.
  const long double index[3] = { static_cast<long double>(x), static_cast<long double>(y),
    static_cast<long double>(z) };
  long double world[3];
  for (int r = 0; r < 3; ++r)
  {
    world[r] = s.origin[r];
    for (int c = 0; c < 3; ++c)
      world[r] += d[3 * r + c] * s.spacing[c] * index[c];
  }
  long double total = 0;
  for (int i = 0; i < s.rays; ++i)
  {
    const long double zi = 1 - (2.0L * i + 1) / s.rays;
    const long double ri = std::sqrt(1 - zi * zi);
    const long double phi = (i + 0.5L) * pi * (3 - std::sqrt(5.0L));
    const long double w[3] = { ri * std::cos(phi), ri * std::sin(phi), zi };
    long double depth = 0;
    for (std::int64_t k = 0; k < m; ++k)
    {
      long double p[3], q[3];
      for (int r = 0; r < 3; ++r)
        p[r] = world[r] + (k + 0.5L) * dt * w[r] - s.origin[r];
      // Back to index coordinates: diag(1/h) D^T (p - origin).
      for (int c = 0; c < 3; ++c)
        q[c] = (d[c] * p[0] + d[3 + c] * p[1] + d[6 + c] * p[2]) / s.spacing[c];
      const long double v = valueAt(s, q[0], q[1], q[2]);
      if (std::isnan(static_cast<double>(v)))
        continue; // open sky outside the volume
      const double alpha = std::min(rampOpacity(s.opacity, static_cast<double>(v)), 1 - 1e-6);
      depth += -std::log(1.0L - alpha) / s.unit;
    }
    total += std::exp(-dt * depth);
  }
  return static_cast<double>(total / s.rays);
}

vao::AmbientOcclusionParameters parametersOf(const Scene& s)
{
  vao::AmbientOcclusionParameters p;
  p.method = vao::Method::ExactRays;
  p.opacity = s.opacity;
  p.rays.radius = s.radius;
  p.rays.spacing = s.spacing;
  p.rays.direction = s.direction;
  p.rays.opacityUnitDistance = s.unit;
  p.rays.rayCount = s.rays;
  const std::array<int, 3> reach = vao::rayReach(p.rays);
  p.radius = { reach[0], reach[1], reach[2] };
  return p;
}

std::vector<float> run(const Scene& s, const vao::Region& region, int threads = 0)
{
  std::vector<float> out(static_cast<std::size_t>(region.voxelCount()), -1.0f);
  vao::AmbientOcclusionOutput output;
  output.openness = out.data();
  vao::Execution execution;
  execution.threads = threads;
  const vao::Status status = vao::computeAmbientOcclusion(
    vaotest::viewOf(s.values, s.dims), region, parametersOf(s), output, execution);
  EXPECT_TRUE(status.ok) << status.message;
  return out;
}

/// A ball of dense material in a lighter medium, with random texture.
Scene blobScene(const vao::Index3& dims, unsigned seed)
{
  Scene s;
  s.dims = dims;
  s.values = vaotest::randomVolume<float>(dims, 0.0, 40.0, seed);
  for (std::int64_t z = 0; z < dims[2]; ++z)
    for (std::int64_t y = 0; y < dims[1]; ++y)
      for (std::int64_t x = 0; x < dims[0]; ++x)
      {
        const double r = std::hypot(x - dims[0] / 2.0, y - dims[1] / 3.0, z - dims[2] / 2.0);
        if (r < 3.5)
          s.values[static_cast<std::size_t>((z * dims[1] + y) * dims[0] + x)] += 100.0f;
      }
  s.origin = { -3.0, 2.5, 10.0 };
  s.spacing = { 1.0, 1.5, 2.0 };
  s.direction = { 1, 0, 0, 0, 1, 0, 0, 0, 1 };
  s.opacity.nodes = { { 20.0, 0.0 }, { 60.0, 0.3 }, { 110.0, 0.9 }, { 140.0, 1.0 } };
  s.radius = 4.0;
  s.unit = 0.0; // the smallest spacing
  s.rays = 40;
  return s;
}

double worstDifference(const Scene& s, const vao::Region& region, const std::vector<float>& out)
{
  Scene withUnit = s;
  withUnit.unit = s.unit > 0 ? s.unit : std::min({ s.spacing[0], s.spacing[1], s.spacing[2] });
  double worst = 0;
  for (std::int64_t k = 0; k < region.size[2]; ++k)
    for (std::int64_t j = 0; j < region.size[1]; ++j)
      for (std::int64_t i = 0; i < region.size[0]; ++i)
      {
        const double expected =
          referenceAo(withUnit, region.begin[0] + i, region.begin[1] + j, region.begin[2] + k);
        const float got =
          out[static_cast<std::size_t>((k * region.size[1] + j) * region.size[0] + i)];
        worst = std::max(worst, std::abs(got - expected));
      }
  return worst;
}

} // namespace

TEST(ExactRays, MatchesTheDefinitionOnAnisotropicVoxels)
{
  const Scene s = blobScene({ 11, 9, 8 }, 3);
  const vao::Region whole{ { 0, 0, 0 }, s.dims };
  EXPECT_LE(worstDifference(s, whole, run(s, whole)), 2e-6);
}

TEST(ExactRays, MatchesTheDefinitionInARotatedFrame)
{
  Scene s = blobScene({ 10, 9, 7 }, 4);
  // 30 degrees about (1, 2, 2) / 3, then a reflection of the third axis.
  const double c = std::cos(0.5235987755982988), n = 1 - c, sn = std::sin(0.5235987755982988);
  const double a[3] = { 1 / 3.0, 2 / 3.0, 2 / 3.0 };
  for (int r = 0; r < 3; ++r)
    for (int k = 0; k < 3; ++k)
    {
      double value = a[r] * a[k] * n + (r == k ? c : 0);
      const int e = 3 - r - k; // the axis of the cross term, for r != k
      if (r != k)
        value += ((r + 1) % 3 == k ? -1 : 1) * a[e] * sn;
      s.direction[3 * r + k] = k == 2 ? -value : value;
    }
  s.radius = 3.3;
  s.unit = 0.7;
  s.rays = 33;
  const vao::Region part{ { 1, 2, 0 }, { 8, 5, 7 } };
  EXPECT_LE(worstDifference(s, part, run(s, part)), 2e-6);
}

TEST(ExactRays, EmptyFunctionIsOpenAndUniformMediumTransmitsItsOpacity)
{
  Scene s = blobScene({ 15, 15, 15 }, 5);
  const vao::Region whole{ { 0, 0, 0 }, s.dims };
  s.opacity.nodes = { { 0.0, 0.0 } };
  for (const float v : run(s, whole))
    ASSERT_EQ(v, 1.0f);
  // A uniform alpha: every ray that stays inside transmits (1 - alpha)^(R / u).
  s.opacity.nodes = { { 0.0, 0.25 } };
  s.spacing = { 1.0, 1.0, 1.0 };
  s.radius = 5.0;
  s.unit = 2.0;
  const std::vector<float> out = run(s, whole);
  EXPECT_NEAR(out[(7 * 15 + 7) * 15 + 7], std::pow(0.75, 5.0 / 2.0), 1e-6);
}

TEST(ExactRays, PieceGrownByTheReachGivesTheWholeResult)
{
  const Scene s = blobScene({ 24, 20, 18 }, 6);
  const vao::Region whole{ { 0, 0, 0 }, s.dims };
  const std::vector<float> all = run(s, whole, 2);
  vao::AmbientOcclusionParameters p = parametersOf(s);
  const vao::Index3 lo = { 9, 6, 7 }, size = { 6, 5, 4 };
  // The block: the piece grown by the reach, clipped to the whole extent.
  vao::Index3 blockLo, blockDims;
  for (int a = 0; a < 3; ++a)
  {
    const int reach = a == 0 ? p.radius.x : a == 1 ? p.radius.y : p.radius.z;
    blockLo[a] = std::max<std::int64_t>(0, lo[a] - reach);
    blockDims[a] = std::min<std::int64_t>(s.dims[a], lo[a] + size[a] + reach) - blockLo[a];
  }
  Scene block = s;
  block.dims = blockDims;
  block.values.clear();
  for (std::int64_t z = 0; z < blockDims[2]; ++z)
    for (std::int64_t y = 0; y < blockDims[1]; ++y)
      for (std::int64_t x = 0; x < blockDims[0]; ++x)
        block.values.push_back(s.values[static_cast<std::size_t>(
          ((z + blockLo[2]) * s.dims[1] + y + blockLo[1]) * s.dims[0] + x + blockLo[0])]);
  const vao::Region region{ { lo[0] - blockLo[0], lo[1] - blockLo[1], lo[2] - blockLo[2] }, size };
  const std::vector<float> piece = run(block, region, 1);
  for (std::int64_t z = 0; z < size[2]; ++z)
    for (std::int64_t y = 0; y < size[1]; ++y)
      for (std::int64_t x = 0; x < size[0]; ++x)
        ASSERT_EQ(piece[static_cast<std::size_t>((z * size[1] + y) * size[0] + x)],
          all[static_cast<std::size_t>(
            ((z + lo[2]) * s.dims[1] + y + lo[1]) * s.dims[0] + x + lo[0])])
          << "voxel " << x << ", " << y << ", " << z << " of the piece";
}

TEST(ExactRays, RefusesBadRays)
{
  const Scene s = blobScene({ 6, 6, 6 }, 7);
  const vao::Region whole{ { 0, 0, 0 }, s.dims };
  std::vector<float> out(static_cast<std::size_t>(whole.voxelCount()));
  vao::AmbientOcclusionOutput output;
  output.openness = out.data();
  const auto refused = [&](void (*change)(vao::AmbientOcclusionParameters&), const char* words)
  {
    vao::AmbientOcclusionParameters p = parametersOf(s);
    change(p);
    const vao::Status status =
      vao::computeAmbientOcclusion(vaotest::viewOf(s.values, s.dims), whole, p, output);
    EXPECT_FALSE(status.ok);
    EXPECT_NE(status.message.find(words), std::string::npos) << status.message;
  };
  refused([](vao::AmbientOcclusionParameters& p) { p.rays.radius = 0.0; }, "radius");
  refused([](vao::AmbientOcclusionParameters& p) { p.rays.radius = NAN; }, "radius");
  refused([](vao::AmbientOcclusionParameters& p) { p.rays.rayCount = 0; }, "ray count");
  refused([](vao::AmbientOcclusionParameters& p) { p.rays.spacing[1] = -1.0; }, "spacing");
  refused(
    [](vao::AmbientOcclusionParameters& p) { p.rays.opacityUnitDistance = -2.0; }, "unit distance");
  refused([](vao::AmbientOcclusionParameters& p) { p.rays.direction[1] = 0.5; }, "direction");
  refused([](vao::AmbientOcclusionParameters& p) { p.rays.radius = 1e300; }, "smaller radius");
  refused([](vao::AmbientOcclusionParameters& p) { p.opacity.nodes.clear(); }, "no points");
  refused(
    [](vao::AmbientOcclusionParameters& p)
    {
      p.opacity.logScale = true;
      p.opacity.nodes = { { 1.0, 0.5 } };
    },
    "log");
}
