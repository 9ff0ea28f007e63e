// The Transfer Function method against a brute-force box mean of the opacity, written here
// from docs/methods.md section 10 with its own piecewise-linear opacity (the library's
// evaluation of VTK's curves is checked against vtkPiecewiseFunction itself in
// Testing/Cxx/TestTransferFunctionAO.cxx).
#include "ResultComparison.h"
#include "TestVolumes.h"

#include "vao/AmbientOcclusion.h"
#include "vao/TransferFunction.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

namespace
{

/// Straight lines between the nodes (midpoint 0.5, sharpness 0); outside them the end
/// node's opacity when clamping, else 0. A value on the first node counts as outside, one
/// on the last as inside, as VTK 9.2 has it.
double linearOpacity(const vao::OpacityFunction& f, double v)
{
  const auto& n = f.nodes;
  if (v <= n.front().x || v > n.back().x)
    return f.clamping ? (v <= n.front().x ? n.front().y : n.back().y) : 0.0;
  std::size_t k = 0;
  while (v > n[k + 1].x)
    ++k;
  const double t = (v - n[k].x) / (n[k + 1].x - n[k].x);
  return (1 - t) * n[k].y + t * n[k + 1].y;
}

/// 1 - the mean opacity of the clipped box around (x, y, z), summed in long double.
template <class T>
double bruteForceOpenness(const std::vector<T>& v, const vao::Index3& d, const vao::Radius& r,
  const vao::OpacityFunction& f, std::int64_t x, std::int64_t y, std::int64_t z)
{
  long double sum = 0;
  std::int64_t count = 0;
  for (std::int64_t k = std::max<std::int64_t>(0, z - r.z); k <= std::min(d[2] - 1, z + r.z); ++k)
    for (std::int64_t j = std::max<std::int64_t>(0, y - r.y); j <= std::min(d[1] - 1, y + r.y); ++j)
      for (std::int64_t i = std::max<std::int64_t>(0, x - r.x); i <= std::min(d[0] - 1, x + r.x);
           ++i, ++count)
        sum += linearOpacity(f, static_cast<double>(v[(k * d[1] + j) * d[0] + i]));
  return static_cast<double>(1.0L - sum / count);
}

vao::OpacityFunction nonMonotone(double lo, double hi, bool clamping)
{
  vao::OpacityFunction f;
  const double w = hi - lo;
  f.nodes = { { lo + 0.1 * w, 0.2 }, { lo + 0.35 * w, 0.9 }, { lo + 0.5 * w, 0.05 },
    { lo + 0.8 * w, 0.6 } };
  f.clamping = clamping;
  return f;
}

template <class T>
void checkAgainstBruteForce(double lo, double hi, unsigned seed)
{
  const vao::Index3 dims = { 13, 11, 9 };
  const std::vector<T> v = vaotest::randomVolume<T>(dims, lo, hi, seed);
  const vao::VolumeView view = vaotest::viewOf(v, dims);
  const vao::Region region{ { 2, 1, 3 }, { 9, 8, 5 } };
  for (const vao::Radius radius :
    { vao::Radius{ 1, 1, 1 }, vao::Radius{ 3, 1, 2 }, vao::Radius{ 0, 4, 6 } })
    for (const bool clamping : { true, false })
    {
      vao::AmbientOcclusionParameters p;
      p.method = vao::Method::TransferFunction;
      p.radius = radius;
      p.opacity = nonMonotone(lo, hi, clamping);
      std::vector<float> out(static_cast<std::size_t>(region.voxelCount()), -1.0f);
      vao::AmbientOcclusionOutput output;
      output.openness = out.data();
      const vao::Status status = vao::computeAmbientOcclusion(view, region, p, output);
      ASSERT_TRUE(status.ok) << status.message;
      double worst = 0;
      for (std::int64_t k = 0; k < region.size[2]; ++k)
        for (std::int64_t j = 0; j < region.size[1]; ++j)
          for (std::int64_t i = 0; i < region.size[0]; ++i)
          {
            const double expected = bruteForceOpenness(v, dims, radius, p.opacity,
              region.begin[0] + i, region.begin[1] + j, region.begin[2] + k);
            worst = std::max(
              worst, std::abs(out[(k * region.size[1] + j) * region.size[0] + i] - expected));
          }
      EXPECT_LE(worst, 1e-6) << "radius " << radius.x << "," << radius.y << "," << radius.z
                             << " clamping " << clamping;
    }
}

} // namespace

TEST(TransferFunction, MatchesBruteForceOnEveryType)
{
  checkAgainstBruteForce<std::int8_t>(-128, 127, 1);
  checkAgainstBruteForce<std::uint8_t>(0, 255, 2);
  checkAgainstBruteForce<std::int16_t>(-1000, 3000, 3);
  checkAgainstBruteForce<std::uint16_t>(0, 65535, 4);
  checkAgainstBruteForce<std::int32_t>(-100000, 100000, 5);
  checkAgainstBruteForce<std::uint32_t>(0, 4e9, 6);
  checkAgainstBruteForce<std::int64_t>(-1e12, 1e12, 7);
  checkAgainstBruteForce<std::uint64_t>(0, 1e15, 8);
  checkAgainstBruteForce<float>(-3.5, 2.25, 9);
  checkAgainstBruteForce<double>(-1e-3, 4e-3, 10);
}

/// alpha(v) = (v > c): nodes (c, 0) and (c + 1, 1) clamped give 0 up to c and 1 from
/// c + 1 on integer data, so O_tf counts the voxels at or below c: Exact Box's iso query.
template <class T>
void checkStepIsExactBox(double lo, double hi, double c)
{
  const vao::Index3 dims = { 17, 12, 10 };
  const std::vector<T> v = vaotest::randomVolume<T>(dims, lo, hi, 21);
  const vao::VolumeView view = vaotest::viewOf(v, dims);
  const vao::Region region = vao::Region::whole(view);
  vao::AmbientOcclusionParameters tf;
  tf.method = vao::Method::TransferFunction;
  tf.radius = { 3, 2, 4 };
  tf.opacity.nodes = { { c, 0.0 }, { c + 1, 1.0 } };
  vao::AmbientOcclusionParameters box = tf;
  box.method = vao::Method::ExactBox;
  box.queryMode = vao::QueryMode::IsoValue;
  box.isoValue = c;
  std::vector<float> a(static_cast<std::size_t>(region.voxelCount())), b(a.size());
  vao::AmbientOcclusionOutput oa, ob;
  oa.openness = a.data();
  ob.openness = b.data();
  ASSERT_TRUE(vao::computeAmbientOcclusion(view, region, tf, oa).ok);
  ASSERT_TRUE(vao::computeAmbientOcclusion(view, region, box, ob).ok);
  EXPECT_TRUE(vaotest::sameBits(a, b));
}

TEST(TransferFunction, StepEqualsExactBoxIsoQueryBitForBit)
{
  checkStepIsExactBox<std::uint8_t>(0, 255, 100);
  checkStepIsExactBox<std::int16_t>(-1000, 3000, 17);
  checkStepIsExactBox<std::uint16_t>(0, 4000, 2500);
  checkStepIsExactBox<std::int32_t>(-50, 50, 0);
}

TEST(TransferFunction, SameBitsOnAnyThreadCount)
{
  const vao::Index3 dims = { 40, 33, 29 };
  const std::vector<float> v = vaotest::randomVolume<float>(dims, 0, 1, 5);
  const vao::VolumeView view = vaotest::viewOf(v, dims);
  vao::AmbientOcclusionParameters p;
  p.method = vao::Method::TransferFunction;
  p.radius = { 5, 5, 5 };
  p.opacity.nodes = { { 0.2, 0.0, 0.3, 0.6 }, { 0.5, 0.7, 0.8, 0.2 }, { 0.9, 0.1 } };
  std::vector<std::vector<float>> results;
  for (int threads : { 1, 2, 3, 7 })
  {
    std::vector<float> out(static_cast<std::size_t>(view.voxelCount()));
    vao::AmbientOcclusionOutput o;
    o.openness = out.data();
    vao::Execution e;
    e.threads = threads;
    ASSERT_TRUE(vao::computeAmbientOcclusion(view, vao::Region::whole(view), p, o, e).ok);
    results.push_back(out);
  }
  for (std::size_t k = 1; k < results.size(); ++k)
    EXPECT_TRUE(vaotest::sameBits(results[0], results[k])) << "threads differ";
}

TEST(TransferFunction, RefusesBadFunctions)
{
  const vao::Index3 dims = { 8, 8, 8 };
  const std::vector<float> v = vaotest::randomVolume<float>(dims, -1, 1, 3);
  const vao::VolumeView view = vaotest::viewOf(v, dims);
  std::vector<float> out(512, -7.0f);
  vao::AmbientOcclusionOutput o;
  o.openness = out.data();
  const auto run = [&](const vao::OpacityFunction& f)
  {
    vao::AmbientOcclusionParameters p;
    p.method = vao::Method::TransferFunction;
    p.radius = { 2, 2, 2 };
    p.opacity = f;
    return vao::computeAmbientOcclusion(view, vao::Region::whole(view), p, o);
  };
  const auto expectRefused = [&](const vao::OpacityFunction& f, const std::string& words)
  {
    const vao::Status s = run(f);
    EXPECT_FALSE(s.ok);
    EXPECT_NE(s.message.find(words), std::string::npos) << s.message;
  };
  expectRefused({}, "no points");
  expectRefused({ { { 0.0, std::nan("") } } }, "not finite");
  expectRefused({ { { std::numeric_limits<double>::infinity(), 0.5 } } }, "not finite");
  expectRefused({ { { 0.0, 1.5 } } }, "[0, 1]");
  expectRefused({ { { 0.0, -0.1 } } }, "[0, 1]");
  expectRefused({ { { 0.0, 0.5, 1.2, 0.0 } } }, "midpoint and sharpness");
  expectRefused({ { { 1.0, 0.5 }, { 0.0, 0.2 } } }, "ascending");
  // A log scale over values at or below 0: VTK's curve is NaN there.
  const vao::OpacityFunction logScale{ { { -0.5, 0.0 }, { 1.0, 1.0 } }, true, true };
  expectRefused(logScale, "log scale");
  for (float value : out)
    ASSERT_EQ(value, -7.0f); // nothing written
}

TEST(TransferFunction, ValuesOnNodesFollowEitherVtkConvention)
{
  // Nodes with equal x inside and at the ends (ParaView's editor allows them), in the
  // order VTK keeps them; the expected opacities are vtkPiecewiseFunction::GetValue's,
  // recorded from VTK 9.2 (Debian 12) and VTK 9.3 (Debian 13). Off the nodes they agree; on
  // a node 9.2 ends the segment that reaches it and 9.3 starts the one that leaves it.
  vao::OpacityFunction f;
  f.nodes = { { -10, 0.2, 0.5, 0 }, { 0, 0.3, 0.3, 0.6 }, { 0, 0.9, 0.6, 0.1 }, { 5, 0.5, 0.5, 0 },
    { 5, 0.1, 0.5, 0 }, { 5, 0.6, 0.2, 0.8 }, { 20, 0.4, 0.5, 0 } };
  const double x[] = { -10, 0, std::nextafter(0.0, -1.0), std::nextafter(0.0, 1.0), 2, 5,
    std::nextafter(5.0, 0.0), std::nextafter(5.0, 10.0), 12, 20 };
  struct Case
  {
    bool startSegments, clamping;
    double expected[10];
  };
  const Case cases[] = {
    { false, false, { 0.0, 0.3, 0.3, 0.9, 0.814952, 0.5, 0.5, 0.6, 0.400601, 0.4 } },
    { false, true, { 0.2, 0.3, 0.3, 0.9, 0.814952, 0.5, 0.5, 0.6, 0.400601, 0.4 } },
    { true, false, { 0.2, 0.9, 0.3, 0.9, 0.814952, 0.6, 0.5, 0.6, 0.400601, 0.0 } },
    { true, true, { 0.2, 0.9, 0.3, 0.9, 0.814952, 0.6, 0.5, 0.6, 0.400601, 0.4 } },
  };
  for (const Case& c : cases)
  {
    f.nodesStartSegments = c.startSegments;
    f.clamping = c.clamping;
    for (int i = 0; i < 10; ++i)
      EXPECT_NEAR(vao::evaluateOpacity(f, x[i]), c.expected[i], 1e-6)
        << "x " << x[i] << ", nodes start segments " << c.startSegments << ", clamping "
        << c.clamping;
  }
}

TEST(TransferFunction, SharpSegmentsStepOrCurveAsEitherVtk)
{
  // Sharpness 1 from 0 to 10 (midpoint 0.5), then linear to 20: VTK 9.2 steps at the
  // midpoint, VTK 9.3 follows the Hermite curve (GetValue's values from both).
  vao::OpacityFunction f;
  f.nodes = { { 0, 0.0, 0.5, 1.0 }, { 10, 1.0, 0.5, 0.0 }, { 20, 0.0, 0.5, 0.0 } };
  const double x[] = { 1, 3, 4.9, 5, 5.1, 7, 9 };
  const double step[] = { 0, 0, 0, 1, 1, 1, 1 };
  const double curve[] = { 0.0, 1e-05, 0.352527, 0.5, 0.647473, 0.99999, 1.0 };
  for (int i = 0; i < 7; ++i)
  {
    f.sharpSegmentsStep = true;
    EXPECT_NEAR(vao::evaluateOpacity(f, x[i]), step[i], 1e-6) << x[i];
    f.sharpSegmentsStep = false;
    EXPECT_NEAR(vao::evaluateOpacity(f, x[i]), curve[i], 1e-6) << x[i];
  }
}

TEST(TransferFunction, InterpolationSearchFindsEvenNodesSegments)
{
  // On evenly spaced nodes VTK 9.3's interpolation search finds the bisection's segment
  // for any value between nodes (its quirks are on the nodes themselves).
  vao::OpacityFunction f;
  for (int i = 0; i <= 300; ++i)
    f.nodes.push_back({ 0.25 * i, std::fmod(0.37 * i, 1.0), 0.5, 0.0 });
  for (double x = -1.0; x < 76.0; x += 0.0123)
  {
    const bool onNode = std::fmod(x, 0.25) == 0.0;
    if (onNode)
      continue;
    f.interpolationSearch = false;
    const double bisection = vao::evaluateOpacity(f, x);
    f.interpolationSearch = true;
    EXPECT_DOUBLE_EQ(vao::evaluateOpacity(f, x), bisection) << x;
  }
}
