// Occlusion sweeping: the combination of the octants into AmbientOcclusion, progress and
// cancellation, and the validation of the arguments.
#include "SweepTestSupport.h"

#include <gtest/gtest.h>

#include <functional>
#include <map>

using namespace vaotest;

namespace
{

constexpr double kPi = 3.14159265358979323846;

// ---------------------------------------------------------------------------------------
// Ambient occlusion: the octants combined

/// N from the D that the kernel returned: central differences, one-sided at the borders.
std::array<double, 3> normalOf(const Result& r, const vao::Index3& d, const Spacing& h,
  std::int64_t x, std::int64_t y, std::int64_t z)
{
  const std::int64_t p[3] = { x, y, z };
  std::array<double, 3> n{};
  double length = 0;
  for (int a = 0; a < 3; ++a)
  {
    std::int64_t lo[3] = { x, y, z }, hi[3] = { x, y, z };
    lo[a] = std::max<std::int64_t>(0, p[a] - 1);
    hi[a] = std::min<std::int64_t>(d[a] - 1, p[a] + 1);
    auto at = [&](const std::int64_t* q)
    { return double(r.distance[(q[2] * d[1] + q[1]) * d[0] + q[0]]); };
    n[a] = (at(hi) - at(lo)) / ((hi[a] - lo[a]) * h[a]);
    length += n[a] * n[a];
  }
  length = std::sqrt(length);
  for (double& c : n)
    c = length > 0 ? c / length : 0;
  if (!(length > 0))
    n = { 0, 0, 1 };
  return n;
}

TEST(SweepOcclusion, CombinesTheMaskedOctants)
{
  const Scene scene = makeScene({ 23, 19, 21 }, { 1, 1.2, 0.9 }, spheresAndBox());
  const std::array<bool, 8> cloudy = { false, false, false, false, true, true, true, true };
  for (bool geometry : { false, true })
    for (double opacity : { 1.0, 0.5 })
      for (const auto& mask : { vao::SweepParameters{}.octantMask, cloudy })
      {
        SCOPED_TRACE(
          std::string(geometry ? "geometry" : "mean") + ", opacity " + std::to_string(opacity));
        vao::SweepParameters p;
        p.useGeometryTerm = geometry;
        p.opacity = opacity;
        p.octantMask = mask;
        const Result r = sweep(scene.view(), scene.spacing, p);
        ASSERT_TRUE(r.status.ok);
        p.gamma = 2.0;
        const Result brighter = sweep(scene.view(), scene.spacing, p, 0, false);
        const bool twoSided = opacity < 1.0;
        std::int64_t i = 0;
        for (std::int64_t z = 0; z < scene.dims[2]; ++z)
          for (std::int64_t y = 0; y < scene.dims[1]; ++y)
            for (std::int64_t x = 0; x < scene.dims[0]; ++x, ++i)
            {
              const auto n = normalOf(r, scene.dims, scene.spacing, x, y, z);
              double sum = 0, weights = 0;
              for (int s = 0; s < 8; ++s)
                if (mask[s])
                {
                  const double w = geometry ? vao::geometryTerm(s, n, twoSided) : 1.0;
                  sum += w * r.octant(i, s);
                  weights += geometry ? 0.0 : 1.0;
                }
              const double expected =
                std::min(1.0, sum / (geometry ? (twoSided ? 2 * kPi : kPi) : weights));
              ASSERT_NEAR(r.occlusion[i], expected, 2e-6) << x << "," << y << "," << z;
              ASSERT_NEAR(brighter.occlusion[i], std::sqrt(expected), 2e-6);
            }
      }
}

TEST(SweepExecution, ReportsProgressAndCancels)
{
  const Scene scene = makeScene({ 19, 17, 21 }, { 1, 1, 1 }, spheresAndBox());
  std::vector<double> seen;
  vao::Execution execution;
  execution.threads = 2;
  execution.progress = [&](double p) { seen.push_back(p); };
  std::vector<float> ao(scene.values.size());
  vao::SweepParameters p = withIterations(2);
  EXPECT_TRUE(vao::computeOcclusionSweeping(
    scene.view(), scene.spacing, p, { nullptr, ao.data(), nullptr }, execution)
                .ok);
  ASSERT_FALSE(seen.empty());
  EXPECT_TRUE(std::is_sorted(seen.begin(), seen.end()));
  EXPECT_GE(seen.front(), 0.0);
  EXPECT_DOUBLE_EQ(seen.back(), 1.0);

  int polls = 0;
  execution.abortRequested = [&] { return ++polls > 30; };
  const vao::Status status = vao::computeOcclusionSweeping(
    scene.view(), scene.spacing, p, { nullptr, ao.data(), nullptr }, execution);
  EXPECT_FALSE(status.ok);
  EXPECT_TRUE(status.aborted);
}

TEST(SweepValidation, RejectsBadArgumentsWithAReason)
{
  const vao::Index3 dims{ 6, 5, 4 };
  std::vector<float> values(6 * 5 * 4, 0.0f);
  values[3] = 1.0f;
  std::vector<float> out(values.size());
  const vao::SweepOutput output{ out.data(), nullptr, nullptr };
  const vao::SweepOutput withAo{ nullptr, out.data(), nullptr };
  const Spacing h{ 1, 1, 1 };
  auto expectRejected = [&](const vao::VolumeView& view, const Spacing& spacing,
                          const vao::SweepParameters& p, const vao::SweepOutput& o,
                          const char* what)
  {
    const vao::Status status = vao::computeOcclusionSweeping(view, spacing, p, o);
    EXPECT_FALSE(status.ok) << what;
    EXPECT_FALSE(status.aborted) << what;
    EXPECT_FALSE(status.message.empty()) << what;
    return status.message;
  };
  const vao::SweepParameters good;
  expectRejected(vao::VolumeView{}, h, good, output, "empty");
  expectRejected(viewOf(values, { 30, 4, 1 }), h, good, output, "2-D");
  expectRejected(viewOf(values, { 120, 1, 1 }), h, good, output, "1-D");
  vao::VolumeView noStride = viewOf(values, dims);
  noStride.voxelStride = 0;
  expectRejected(noStride, h, good, output, "stride");
  const double inf = std::numeric_limits<double>::infinity(), nan = std::nan("");
  for (const Spacing& bad :
    { Spacing{ 0, 1, 1 }, Spacing{ 1, -1, 1 }, Spacing{ 1, 1, inf }, Spacing{ nan, 1, 1 } })
    expectRejected(viewOf(values, dims), bad, good, output, "spacing");
  auto rejects = [&](auto change, const char* what, const vao::SweepOutput& o)
  {
    vao::SweepParameters p;
    change(p);
    return expectRejected(viewOf(values, dims), h, p, o, what);
  };
  rejects([&](vao::SweepParameters& p) { p.isoValue = nan; }, "iso NaN", output);
  rejects([&](vao::SweepParameters& p) { p.isoValue = inf; }, "iso inf", output);
  rejects([](vao::SweepParameters& p) { p.iterations = 0; }, "iterations", output);
  rejects([](vao::SweepParameters& p) { p.tolerance = -1e-3; }, "tolerance", output);
  rejects([&](vao::SweepParameters& p) { p.tolerance = nan; }, "tolerance NaN", output);
  rejects([](vao::SweepParameters& p) { p.gamma = 0; }, "gamma", output);
  rejects([&](vao::SweepParameters& p) { p.gamma = inf; }, "gamma inf", output);
  rejects([](vao::SweepParameters& p) { p.opacity = 1.5; }, "opacity", output);
  rejects([](vao::SweepParameters& p) { p.opacity = -0.1; }, "opacity", output);
  rejects([&](vao::SweepParameters& p) { p.opacity = nan; }, "opacity NaN", output);
  rejects([](vao::SweepParameters& p) { p.octantMask.fill(false); }, "mask", withAo);
  // With no occlusion requested the mask does not matter.
  vao::SweepParameters noOctants;
  noOctants.octantMask.fill(false);
  EXPECT_TRUE(vao::computeOcclusionSweeping(viewOf(values, dims), h, noOctants, output).ok);

  values[7] = std::numeric_limits<float>::quiet_NaN();
  values[9] = std::numeric_limits<float>::infinity();
  const std::string message = expectRejected(viewOf(values, dims), h, good, output, "non-finite");
  EXPECT_NE(message.find("2 non-finite"), std::string::npos) << message;
}

} // namespace
