// Occlusion sweeping (Singh, Yuksel & House 2009) against exact distance fields, a
// brute-force evaluation of Eq. 6, the symmetries of the octants, the closed-form geometry
// term against quadrature, and the validation of the arguments.
#include "SweepTestSupport.h"

#include <gtest/gtest.h>

#include <functional>
#include <map>

using namespace vaotest;

namespace
{

constexpr double kPi = 3.14159265358979323846;

// ---------------------------------------------------------------------------------------
// Signed distance

struct DistanceCase
{
  const char* name;
  Scene scene;
  double bound;        // measured max |D - exact| after one pass (world units), rounded up
  double boundOutside; // the same outside the surface
};

std::vector<DistanceCase> distanceCases()
{
  const Spacing iso{ 1, 1, 1 }, aniso{ 1, 1.5, 0.8 };
  std::vector<DistanceCase> cases;
  // Radius 20 h; measured 1.029 (the shock at the centre) and 0.628 outside.
  cases.push_back(
    { "sphere R = 20 h", makeScene({ 49, 47, 51 }, iso, sphere(24.3, 23.1, 25.4, 20)), 1.1, 0.7 });
  // Radius 15 (world) = 15 hx = 10 hy = 18.75 hz; measured 1.017 and 0.806.
  cases.push_back({ "anisotropic sphere",
    makeScene({ 41, 37, 45 }, aniso, sphere(20.2, 27.3, 17.7, 15)), 1.1, 0.9 });
  // Corners and edges are point and line sources, the hardest case of a first-order
  // scheme; measured 2.093 (outside) and 2.277.
  cases.push_back(
    { "box", makeScene({ 41, 37, 45 }, iso, box(20.3, 18.2, 22.1, 10, 8, 12)), 2.2, 2.2 });
  cases.push_back({ "anisotropic box",
    makeScene({ 41, 37, 45 }, aniso, box(20.3, 27.2, 17.6, 10, 12, 9)), 2.4, 2.4 });
  // Measured 0.736.
  cases.push_back({ "torus", makeScene({ 45, 45, 31 }, iso, torus(22, 22, 15, 14, 5)), 0.8, 0.8 });
  // Two disjoint spheres: between them, points whose upwind neighbours take their values
  // from the other sphere in a later sweep; measured 1.196 (a corner of the volume).
  const Sdf near = sphere(10, 10, 10, 4), far = sphere(30, 28, 26, 4);
  cases.push_back({ "two spheres",
    makeScene({ 41, 37, 45 }, iso,
      [=](double x, double y, double z) { return std::min(near(x, y, z), far(x, y, z)); }),
    1.25, 1.25 });
  return cases;
}

TEST(SweepDistance, OnePassIsWithinTheMeasuredBoundWithTheRightSign)
{
  for (const DistanceCase& c : distanceCases())
  {
    SCOPED_TRACE(c.name);
    const Result r = sweep(c.scene.view(), c.scene.spacing, vao::SweepParameters{});
    ASSERT_TRUE(r.status.ok) << r.status.message;
    EXPECT_TRUE(r.report.surfaceFound);
    EXPECT_EQ(r.report.passes, 1);
    const Errors e = distanceErrors(c.scene, r.distance);
    EXPECT_LE(e.max, c.bound);
    EXPECT_LE(e.maxOutside, c.boundOutside);
    for (std::size_t i = 0; i < r.distance.size(); ++i)
    {
      ASSERT_EQ(r.distance[i]<0, c.scene.values[i]> 0) << "voxel " << i;
    }
  }
}

TEST(SweepDistance, MorePassesNeverIncreaseTheError)
{
  // The exact distance has straight characteristics, so one pass is nearly converged: for
  // a single object passes 2 and 3 change |D| by 2e-3 h at most and the maximum error
  // stays where one pass put it (at the shock inside a sphere, or around the corners of a
  // box). With two objects, pass 2 still lowers D by 0.2 h between them: the mean error
  // drops by 0.3 % and the maximum error by 2e-5 h (measured).
  bool maxDecreased = false;
  for (const DistanceCase& c : distanceCases())
  {
    SCOPED_TRACE(c.name);
    Errors previous;
    double previousChange = 0;
    for (int iterations = 1; iterations <= 3; ++iterations)
    {
      const Result r = sweep(c.scene.view(), c.scene.spacing, withIterations(iterations), 0, false);
      ASSERT_TRUE(r.status.ok) << r.status.message;
      EXPECT_EQ(r.report.passes, iterations);
      const Errors e = distanceErrors(c.scene, r.distance);
      if (iterations > 1)
      {
        // A few voxels where D was already below the exact distance move further away.
        EXPECT_LE(e.max, previous.max + 1e-6);
        EXPECT_LE(e.mean, previous.mean + 1e-7);
        EXPECT_LT(r.report.lastChange, previousChange);
        EXPECT_LT(r.report.lastChange, 0.25 * c.scene.spacing[0]);
        maxDecreased = maxDecreased || e.max < previous.max - 1e-6;
      }
      previous = e;
      previousChange = r.report.lastChange;
    }
  }
  EXPECT_TRUE(maxDecreased);
}

TEST(SweepDistance, SignFollowsInsideForBothOrientations)
{
  const vao::Index3 dims{ 13, 11, 9 };
  const auto values = randomVolume<std::uint8_t>(dims, 0, 255, 7);
  for (bool above : { true, false })
  {
    vao::SweepParameters p;
    p.isoValue = 127.5;
    p.insideIsAbove = above;
    const Result r = sweep(viewOf(values, dims), { 0.7, 1.1, 0.9 }, p);
    ASSERT_TRUE(r.status.ok) << r.status.message;
    for (std::size_t i = 0; i < values.size(); ++i)
    {
      const bool inside = above ? values[i] > 127.5 : values[i] < 127.5;
      ASSERT_EQ(r.distance[i] < 0, inside) << "voxel " << i;
      ASSERT_TRUE(std::isfinite(r.distance[i]));
    }
  }
}

TEST(SweepDistance, InitialisedPointsHoldTheInterpolatedCrossing)
{
  // A linear ramp along x crosses the iso value between x = 3 and 4 at 3.3: the two points
  // of every such edge are fixed at 0.3 hx and 0.7 hx.
  const vao::Index3 dims{ 9, 5, 4 };
  std::vector<double> values;
  for (std::int64_t z = 0; z < dims[2]; ++z)
    for (std::int64_t y = 0; y < dims[1]; ++y)
      for (std::int64_t x = 0; x < dims[0]; ++x)
        values.push_back(x * 10.0);
  vao::SweepParameters p;
  p.isoValue = 33.0;
  const Result r = sweep(viewOf(values, dims), { 2.0, 1.0, 1.0 }, p);
  ASSERT_TRUE(r.status.ok) << r.status.message;
  for (std::int64_t i = 0; i < dims[0] * dims[1] * dims[2]; ++i)
  {
    const std::int64_t x = i % dims[0];
    // A plane: the sweeps reproduce the exact distance 2 (x - 3.3) everywhere.
    EXPECT_NEAR(r.distance[i], -2.0 * (x - 3.3), 1e-5) << "voxel " << i;
  }
}

TEST(SweepDistance, AnyScalarTypeReadThroughTheStride)
{
  const Scene scene = makeScene({ 17, 15, 19 }, { 1, 1, 1 }, sphere(8.2, 7.1, 9.3, 5.4));
  std::vector<float> quantised(scene.values.size());
  std::vector<std::int16_t> interleaved(3 * scene.values.size(), 9999);
  for (std::size_t i = 0; i < scene.values.size(); ++i)
  {
    quantised[i] = std::round(100.0f * scene.values[i]);
    interleaved[3 * i + 1] = static_cast<std::int16_t>(quantised[i]);
  }
  vao::VolumeView strided = viewOf(interleaved, scene.dims, 3);
  strided.data = interleaved.data() + 1;
  vao::SweepParameters p;
  p.isoValue = 0.5;
  const Result a = sweep(viewOf(quantised, scene.dims), scene.spacing, p);
  const Result b = sweep(strided, scene.spacing, p);
  ASSERT_TRUE(a.status.ok && b.status.ok);
  EXPECT_EQ(a.distance, b.distance);
  EXPECT_EQ(a.octants, b.octants);
  EXPECT_EQ(a.occlusion, b.occlusion);
}

TEST(SweepDistance, ScalesWithTheSpacingDownToTwoVoxelsPerAxis)
{
  // D in world units and tau relative to the smallest spacing: scaling the spacing scales
  // D and leaves V unchanged, from millimetres in metres to kilometres.
  const Scene unit = makeScene({ 2, 3, 2 }, { 1, 1.5, 0.8 }, sphere(0.2, 0.4, 0.3, 0.9));
  const Scene larger = makeScene({ 19, 17, 21 }, { 1, 1.5, 0.8 }, spheresAndBox());
  for (const Scene* scene : { &unit, &larger })
  {
    const Result reference = sweep(scene->view(), scene->spacing, vao::SweepParameters{});
    ASSERT_TRUE(reference.status.ok) << reference.status.message;
    for (double scale : { 1e-3, 1e3 })
    {
      const Spacing h{ scene->spacing[0] * scale, scene->spacing[1] * scale,
        scene->spacing[2] * scale };
      const Result scaled = sweep(scene->view(), h, vao::SweepParameters{});
      ASSERT_TRUE(scaled.status.ok);
      for (std::size_t i = 0; i < reference.distance.size(); ++i)
        ASSERT_NEAR(scaled.distance[i] / scale, reference.distance[i],
          1e-5 * std::max(1.0f, std::abs(reference.distance[i])));
      EXPECT_LT(largestDifference(scaled.octants, reference.octants), 1e-6);
    }
  }
}

TEST(SweepDistance, ToleranceStopsThePasses)
{
  const Scene scene = makeScene({ 41, 37, 45 }, { 1, 1.5, 0.8 }, sphere(20.2, 27.3, 17.7, 15));
  const Result fixed = sweep(scene.view(), scene.spacing, withIterations(4), 0, false);
  EXPECT_EQ(fixed.report.passes, 4);
  const Result early = sweep(scene.view(), scene.spacing, withIterations(20, 1e-3), 0, false);
  ASSERT_TRUE(early.status.ok);
  // The first pass reaches every voxel, so it never counts as converged.
  EXPECT_GE(early.report.passes, 2);
  EXPECT_LT(early.report.passes, 20);
  EXPECT_LT(early.report.lastChange, 1e-3);
  const Result full = sweep(scene.view(), scene.spacing, converged(), 0, false);
  EXPECT_LT(full.report.passes, 50);
  EXPECT_EQ(full.report.lastChange, 0.0);
}

TEST(SweepDistance, ThreadCountDoesNotChangeAnyBit)
{
  // A sweep's result depends only on the upwind order, which the plane pipeline keeps.
  const Scene scene = makeScene({ 29, 23, 31 }, { 1, 0.9, 1.2 }, spheresAndBox());
  vao::SweepParameters p = withIterations(2);
  p.useGeometryTerm = true;
  const Result one = sweep(scene.view(), scene.spacing, p, 1);
  for (int threads : { 2, 3, 7 })
  {
    const Result many = sweep(scene.view(), scene.spacing, p, threads);
    EXPECT_EQ(one.distance, many.distance) << threads << " threads";
    EXPECT_EQ(one.octants, many.octants) << threads << " threads";
    EXPECT_EQ(one.occlusion, many.occlusion) << threads << " threads";
    EXPECT_EQ(one.report.lastChange, many.report.lastChange);
  }
}

TEST(SweepOcclusion, ThreadCountDoesNotChangeAnyBitWithoutKeptOctants)
{
  // Without the octant output (and without the geometry term) V lives in a ring of planes
  // that the pipelined planes overwrite; with more threads than slots a plane would
  // overwrite a row its upwind plane still reads. Flat planes (few rows, many planes) and
  // more threads than cores make that overlap likely; the result must stay bit for bit.
  const Sdf a = sphere(4.1, 3.2, 12.3, 3.1), b = sphere(3.7, 2.9, 31.6, 2.4),
            c = box(4.2, 3.1, 48.2, 2.5, 9.0, 4.1);
  const Scene scene = makeScene({ 9, 7, 61 }, { 1, 1, 1 }, [=](double x, double y, double z) {
    return std::min({ a(x, y, z), b(x, y, z), c(x, y, z) });
  });
  vao::SweepParameters p = withIterations(2);
  const Result one = sweep(scene.view(), scene.spacing, p, 1, false);
  for (int repeat = 0; repeat < 20; ++repeat)
    for (int threads : { 3, 5, 8, 16 })
    {
      const Result many = sweep(scene.view(), scene.spacing, p, threads, false);
      ASSERT_EQ(one.distance, many.distance) << threads << " threads";
      ASSERT_EQ(one.occlusion, many.occlusion) << threads << " threads, repeat " << repeat;
    }
}

// ---------------------------------------------------------------------------------------
// Visibility (Eq. 6)

TEST(SweepVisibility, WithoutSurfaceEverythingIsOpenOrClosed)
{
  const vao::Index3 dims{ 7, 6, 5 };
  const std::vector<float> empty(7 * 6 * 5, 0.0f);
  const double diagonal = std::sqrt(6.0 * 6.0 + 7.5 * 7.5 + 4.0 * 4.0);
  for (bool geometry : { false, true })
    for (double iso : { 0.5, -0.5 }) // above the data: all outside (empty); below: all inside
    {
      vao::SweepParameters p;
      p.isoValue = iso;
      p.useGeometryTerm = geometry;
      const Result r = sweep(viewOf(empty, dims), { 1, 1.5, 1 }, p);
      ASSERT_TRUE(r.status.ok) << r.status.message;
      EXPECT_FALSE(r.report.surfaceFound);
      const bool inside = iso < 0;
      const float open = inside ? 0.0f : 1.0f;
      for (std::size_t i = 0; i < empty.size(); ++i)
      {
        ASSERT_FLOAT_EQ(r.distance[i], inside ? -diagonal : diagonal);
        ASSERT_EQ(r.occlusion[i], open);
        for (int s = 0; s < 8; ++s)
          ASSERT_EQ(r.octant(i, s), open);
      }
    }
}

TEST(SweepVisibility, OpenSpaceAroundAnObjectIsExactlyOne)
{
  // Nothing upwind of the voxels before a small sphere in the sweep order of octant 0.
  const Scene scene = makeScene({ 21, 19, 23 }, { 1, 1, 1 }, sphere(14, 13, 16, 3));
  const Result r = sweep(scene.view(), scene.spacing, vao::SweepParameters{});
  ASSERT_TRUE(r.status.ok);
  for (std::int64_t z = 0; z < 10; ++z)
    for (std::int64_t y = 0; y < 8; ++y)
      for (std::int64_t x = 0; x < 9; ++x)
        ASSERT_EQ(r.octant(scene.index(x, y, z), 0), 1.0f);
}

TEST(SweepVisibility, ClosedShellDarkensItsInside)
{
  const Sdf outer = box(15, 14, 16, 9, 8, 10), inner = box(15, 14, 16, 6, 5, 7);
  const Scene scene = makeScene({ 31, 29, 33 }, { 1, 1, 1 },
    [&](double x, double y, double z) { return std::max(outer(x, y, z), -inner(x, y, z)); });
  const Result r = sweep(scene.view(), scene.spacing, vao::SweepParameters{});
  ASSERT_TRUE(r.status.ok);
  for (std::int64_t z = 11; z <= 21; ++z)
    for (std::int64_t y = 11; y <= 17; ++y)
      for (std::int64_t x = 11; x <= 19; ++x)
      {
        const std::int64_t i = scene.index(x, y, z);
        for (int s = 0; s < 8; ++s)
          ASSERT_LT(r.octant(i, s), 0.05f) << "octant " << s << " at " << x << "," << y << "," << z;
        ASSERT_LT(r.occlusion[i], 0.05f);
      }
  // Outside, beside the shell, the octants that look away from it are open.
  EXPECT_GT(r.octant(scene.index(2, 2, 2), 0), 0.99f);
}

TEST(SweepVisibility, FloorBlocksTheOctantsBelow)
{
  // A slab z <= 4: sweeps moving up (s = 0..3) read P - h z and carry the light from
  // below, which the floor blocks; s = 4..7 carry the light from above.
  const vao::Index3 dims{ 31, 29, 33 };
  std::vector<float> values;
  for (std::int64_t z = 0; z < dims[2]; ++z)
    for (std::int64_t i = 0; i < dims[0] * dims[1]; ++i)
      values.push_back(z <= 4 ? 1.0f : 0.0f);
  vao::SweepParameters p;
  p.isoValue = 0.5;
  const Result r = sweep(viewOf(values, dims), { 1, 1, 1 }, p);
  ASSERT_TRUE(r.status.ok);
  auto at = [&](std::int64_t x, std::int64_t y, std::int64_t z) {
    return (z * dims[1] + y) * dims[0] + x;
  };
  double below = 0, count = 0;
  for (std::int64_t z = 5; z < dims[2]; ++z)
    for (std::int64_t y = 0; y < dims[1]; ++y)
      for (std::int64_t x = 0; x < dims[0]; ++x)
      {
        const std::int64_t i = at(x, y, z);
        for (int s = 4; s < 8; ++s)
          ASSERT_EQ(r.octant(i, s), 1.0f); // D >= h/2 above the floor: nothing blocks
        for (int s = 0; s < 4; ++s)
          below += r.octant(i, s);
        count += 4;
      }
  EXPECT_LT(below / count, 0.7); // measured 0.645
  // The centre column: dark just above the floor (light from below only leaks in from the
  // volume's sides, which are open sky), brightening with height; the four lower octants
  // are mirror images of each other there.
  float previous = -1.0f;
  for (std::int64_t z = 5; z < dims[2]; ++z)
  {
    const std::int64_t i = at(15, 14, z);
    if (z <= 7)
      EXPECT_LT(r.octant(i, 0), 0.01f) << "z = " << z;
    EXPECT_GT(r.octant(i, 0), previous);
    previous = r.octant(i, 0);
    for (int s = 1; s < 4; ++s)
      EXPECT_EQ(r.octant(i, s), r.octant(i, 0));
  }
  // Inside the slab, below its surface layer, no light at all.
  for (int s = 0; s < 8; ++s)
    EXPECT_EQ(r.octant(at(15, 14, 2), s), 0.0f);
}

/// The volume mirrored along `axis`.
template <class T>
std::vector<T> mirrored(const std::vector<T>& v, const vao::Index3& d, int axis)
{
  std::vector<T> out(v.size());
  for (std::int64_t z = 0; z < d[2]; ++z)
    for (std::int64_t y = 0; y < d[1]; ++y)
      for (std::int64_t x = 0; x < d[0]; ++x)
      {
        std::int64_t p[3] = { x, y, z };
        p[axis] = d[axis] - 1 - p[axis];
        out[(p[2] * d[1] + p[1]) * d[0] + p[0]] = v[(z * d[1] + y) * d[0] + x];
      }
  return out;
}

TEST(SweepVisibility, MirroringSwapsTheOctants)
{
  // Mirroring axis a flips bit a of the octant index (the sign of that sweep direction).
  // V is exactly mirrored: it depends on D only through tau, which is 0 or 1 except on the
  // initialised points (|D| < h/2 needs a straddling edge; a swept value is at least
  // hmin / sqrt(3) from the surface), and those are computed from each point's own side.
  // The swept D is not: the order of the sweeps matters after one pass (up to 0.06 here),
  // and which sweep last lowered a value decides its last bits after convergence.
  const Scene scene = makeScene({ 29, 23, 31 }, { 1, 0.9, 1.2 }, spheresAndBox());
  for (const vao::SweepParameters& passes : { vao::SweepParameters{}, converged() })
  {
    vao::SweepParameters p = passes;
    p.useGeometryTerm = true;
    const Result r = sweep(scene.view(), scene.spacing, p);
    ASSERT_TRUE(r.status.ok);
    for (int axis = 0; axis < 3; ++axis)
    {
      SCOPED_TRACE("axis " + std::to_string(axis) + ", iterations " + std::to_string(p.iterations));
      const auto values = mirrored(scene.values, scene.dims, axis);
      const Result m = sweep(viewOf(values, scene.dims), scene.spacing, p);
      ASSERT_TRUE(m.status.ok);
      for (int s = 0; s < 8; ++s)
      {
        std::vector<float> original(r.distance.size()), swapped(r.distance.size());
        for (std::size_t i = 0; i < original.size(); ++i)
        {
          original[i] = r.octant(i, s);
          swapped[i] = m.octant(i, s ^ (1 << axis));
        }
        EXPECT_EQ(mirrored(original, scene.dims, axis), swapped) << "octant " << s;
      }
      if (p.iterations > 1) // measured: 3.6e-7 relative for D, 1.2e-7 for A (via N)
      {
        EXPECT_LT(
          largestDifference(mirrored(r.distance, scene.dims, axis), m.distance, true), 1e-6);
        EXPECT_LT(largestDifference(mirrored(r.occlusion, scene.dims, axis), m.occlusion), 1e-6);
      }
    }
  }
}

/// Eq. 6 straight from its definition, recursively with memoisation, in double, from a
/// given D: V_s(P) = mean over the upwind neighbours Q = P - dir_a e_a of V_s(Q) tau(Q),
/// with V tau = 1 outside the volume.
class BruteForceVisibility
{
public:
  BruteForceVisibility(
    const vao::Index3& dims, const Spacing& h, const std::vector<float>& d, double opacity)
    : Dims(dims)
    , D(d)
    , Alpha(opacity)
    , HMin(std::min({ h[0], h[1], h[2] }))
  {}

  double operator()(int s, std::int64_t x, std::int64_t y, std::int64_t z)
  {
    const std::int64_t key = ((z * this->Dims[1] + y) * this->Dims[0] + x) * 8 + s;
    const auto found = this->Memo.find(key);
    if (found != this->Memo.end())
      return found->second;
    const auto dir = vao::sweepDirection(s);
    double sum = 0.0;
    for (int a = 0; a < 3; ++a)
    {
      std::int64_t q[3] = { x, y, z };
      q[a] -= dir[a];
      if (q[a] < 0 || q[a] >= this->Dims[a])
      {
        sum += 1.0;
        continue;
      }
      const double d = this->D[(q[2] * this->Dims[1] + q[1]) * this->Dims[0] + q[0]];
      sum += (*this)(s, q[0], q[1], q[2]) * this->tau(d);
    }
    return this->Memo[key] = sum / 3.0;
  }

private:
  double tau(double d) const
  {
    const double h = this->HMin;
    const double opaque = d <= -h / 2 ? 0.0 : (d >= h / 2 ? 1.0 : d / h + 0.5);
    return 1.0 - this->Alpha * (1.0 - opaque); // Eq. 8
  }

  vao::Index3 Dims;
  const std::vector<float>& D;
  double Alpha;
  double HMin;
  std::map<std::int64_t, double> Memo;
};

TEST(SweepVisibility, MatchesEquation6EvaluatedByBruteForce)
{
  const Scene scene = makeScene({ 27, 21, 19 }, { 1.1, 0.8, 1.3 }, spheresAndBox());
  // Converged, the last pass saw the final D; after one pass the V of sweep s saw the D of
  // that moment, which differs from the final one only where tau is 0 or 1 anyway.
  for (const vao::SweepParameters& passes : { vao::SweepParameters{}, converged() })
    for (double opacity : { 1.0, 0.6 })
    {
      SCOPED_TRACE(
        "opacity " + std::to_string(opacity) + ", iterations " + std::to_string(passes.iterations));
      vao::SweepParameters p = passes;
      p.opacity = opacity;
      const Result r = sweep(scene.view(), scene.spacing, p);
      ASSERT_TRUE(r.status.ok);
      BruteForceVisibility reference(scene.dims, scene.spacing, r.distance, opacity);
      double worst = 0.0;
      for (std::int64_t z = 0; z < scene.dims[2]; ++z)
        for (std::int64_t y = 0; y < scene.dims[1]; ++y)
          for (std::int64_t x = 0; x < scene.dims[0]; ++x)
            for (int s = 0; s < 8; ++s)
              worst = std::max(
                worst, std::abs(r.octant(scene.index(x, y, z), s) - reference(s, x, y, z)));
      EXPECT_LT(worst, 1e-6);
    }
}

TEST(SweepVisibility, TransparentOccludersLetAllLightThrough)
{
  const Scene scene = makeScene({ 15, 13, 17 }, { 1, 1, 1 }, spheresAndBox());
  vao::SweepParameters p;
  p.opacity = 0.0;
  const Result r = sweep(scene.view(), scene.spacing, p);
  ASSERT_TRUE(r.status.ok);
  for (float v : r.octants)
    ASSERT_EQ(v, 1.0f);
}

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
    auto at = [&](const std::int64_t* q) {
      return double(r.distance[(q[2] * d[1] + q[1]) * d[0] + q[0]]);
    };
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
                          const char* what) {
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
  auto rejects = [&](auto change, const char* what, const vao::SweepOutput& o) {
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
  static const std::vector<std::array<double, 4>> grid = [] {
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
