// The SurfacePyramid: level 0 in tiles built where the queries sample. Its results must
// be those of the whole pyramid bit for bit (the tiles are the same blur of the same
// voxels), on every SIMD tier, for every query, and it must build only part of level 0.
#include "PyramidTestSupport.h"

#include "cpu/moment_pyramid/LevelTiles.h"
#include "cpu/simd/CpuDispatch.h"

using namespace vaotest;

namespace
{
/// The AO and the shadows of the points on the whole pyramid (buildMomentPyramid): what
/// every SurfacePyramid must give bit for bit.
void wholePyramidAnswers(const Field& f, const std::vector<double>& points,
  const std::vector<double>& normals, const std::array<double, 3>& light, std::vector<float>& ao,
  std::vector<float>& shadow)
{
  const std::int64_t n = static_cast<std::int64_t>(points.size() / 3);
  std::vector<vao::MomentLevel> whole;
  ASSERT_TRUE(vao::buildMomentPyramid(f.view(), f.origin, f.spacing, {}, whole).ok);
  ao.assign(static_cast<std::size_t>(n), -1.0f);
  shadow.assign(static_cast<std::size_t>(n), -1.0f);
  ASSERT_TRUE(vao::surfaceAmbientOcclusion(
    whole, f.view(), f.origin, f.spacing, points.data(), normals.data(), n, {}, ao.data())
                .ok);
  ASSERT_TRUE(
    vao::surfaceShadow(whole, points.data(), normals.data(), n, light, {}, shadow.data()).ok);
}
} // namespace

TEST(SurfacePyramid, TilesHoldTheWholeLevelsVoxels)
{
  // Every tile of levels 0 and 1 built, read back in the layout of LevelTiles.h (tile
  // (tx, ty, tz) at its offset, the (mean, variance) pairs of voxels [8 tx, 8 tx + 9) x
  // ..., x fastest): each voxel, the ninth ones shared with the next tile included,
  // equals the whole level's, at full and half resolution. Level 2, blurred from the two levels
  // streamed slice by slice, equals the whole build's level 2, and so does level 3.
  const Field f = shellScene({ 37, 19, 26 });
  for (bool half : { false, true })
  {
    vao::PyramidParameters p;
    p.levels = 4;
    p.startAtHalfResolution = half;
    std::vector<vao::MomentLevel> whole;
    ASSERT_TRUE(vao::buildMomentPyramid(f.view(), f.origin, f.spacing, p, whole).ok);
    vao::SurfacePyramid surface = surfacePyramidOf(f, p);
    vao::PyramidTiles& tiles = *vao::SurfacePyramidAccess::tiles(surface);
    ASSERT_EQ(tiles.count(), 2);
    for (int l = 0; l < 2; ++l)
    {
      const vao::MomentLevel& level = whole[l];
      vao::detail::LevelTiles& built = *tiles.at(l);
      for (std::int64_t z = 0; z < level.dims[2]; ++z)
        for (std::int64_t y = 0; y < level.dims[1]; ++y)
          for (std::int64_t x = 0; x < level.dims[0]; ++x)
            built.markAround(level.origin[0] + x * level.spacing[0],
              level.origin[1] + y * level.spacing[1], level.origin[2] + z * level.spacing[2]);
    }
    ASSERT_TRUE(tiles.buildMarked({}));
    for (int l = 0; l < 2; ++l)
    {
      const vao::MomentLevel& level = whole[l];
      EXPECT_EQ(surface.builtTiles(l), surface.tileCount(l));
      const vao::detail::LevelGrid grid = tiles.at(l)->grid();
      const std::int64_t tx = (level.dims[0] + 7) / 8, ty = (level.dims[1] + 7) / 8,
                         tz = (level.dims[2] + 7) / 8;
      std::int64_t checked = 0;
      for (std::int64_t tile = 0; tile < tx * ty * tz; ++tile)
      {
        const std::int64_t first[3] = { 8 * (tile % tx), 8 * ((tile / tx) % ty),
          8 * (tile / (tx * ty)) };
        for (std::int64_t k = 0; k < 9 && first[2] + k < level.dims[2]; ++k)
          for (std::int64_t j = 0; j < 9 && first[1] + j < level.dims[1]; ++j)
            for (std::int64_t i = 0; i < 9 && first[0] + i < level.dims[0]; ++i)
            {
              const std::int64_t at = grid.tileOffsets[tile] + 2 * ((k * 9 + j) * 9 + i);
              const std::int64_t x = first[0] + i, y = first[1] + j, z = first[2] + k;
              const std::int64_t v = (z * level.dims[1] + y) * level.dims[0] + x;
              ASSERT_EQ(grid.mean[at], level.mean[v])
                << "level " << l << " half " << half << " voxel " << x << " " << y << " " << z;
              ASSERT_EQ(grid.mean[at + 1], level.variance[v])
                << "level " << l << " half " << half << " voxel " << x << " " << y << " " << z;
              ++checked;
            }
      }
      EXPECT_GT(
        checked, level.dims[0] * level.dims[1] * level.dims[2]); // the shared ninth voxels too
    }
    for (int l = 2; l < 4; ++l)
    {
      const vao::MomentLevel& level = surface.levels()[l];
      ASSERT_EQ(level.mean.size(), whole[l].mean.size());
      for (std::size_t i = 0; i < level.mean.size(); ++i)
      {
        ASSERT_EQ(level.mean[i], whole[l].mean[i]) << "level " << l << " " << i;
        ASSERT_EQ(level.variance[i], whole[l].variance[i]) << "level " << l << " " << i;
      }
    }
  }
}

TEST(SurfacePyramid, QueriesEqualTheWholePyramidBitForBitOnEveryTier)
{
  // A fresh SurfacePyramid per query, so each query finds its own tiles unbuilt: a sample
  // whose tile the marking missed would read zeros and differ.
  const Field f = shellScene({ 45, 38, 41 });
  std::vector<double> points, normals;
  scenePoints(f, points, normals);
  const std::int64_t n = static_cast<std::int64_t>(points.size() / 3);
  const std::vector<std::array<double, 3>> lights = { { 0.2, -0.5, 1 }, { -1, 0, 0 }, { 0, 0, -1 },
    { 0.7, 0.7, -0.1 } };
  for (vao::detail::SimdTier tier :
    { vao::detail::SimdTier::Baseline, vao::detail::SimdTier::Avx2, vao::detail::SimdTier::Avx512 })
  {
    vao::detail::limitSimdTier(tier);
    for (int levels : { 1, 2, 3, 4 })
      for (bool half : { false, true })
      {
        vao::PyramidParameters pp;
        pp.levels = levels;
        pp.startAtHalfResolution = half;
        std::vector<vao::MomentLevel> whole;
        ASSERT_TRUE(vao::buildMomentPyramid(f.view(), f.origin, f.spacing, pp, whole).ok);
        forEachSurfaceQuery(
          [&](vao::SurfaceOcclusionParameters p)
          {
            p.offsetFactor = levels == 2 ? 1.7 : 1.0;
            std::vector<float> expected(n, -1.0f), got(n, -2.0f);
            ASSERT_TRUE(vao::surfaceAmbientOcclusion(whole, f.view(), f.origin, f.spacing,
              points.data(), normals.data(), n, p, expected.data())
                          .ok);
            vao::SurfacePyramid surface = surfacePyramidOf(f, pp);
            const vao::Status s = vao::surfaceAmbientOcclusion(surface, f.view(), f.origin,
              f.spacing, points.data(), normals.data(), n, p, got.data());
            ASSERT_TRUE(s.ok) << s.message;
            for (std::int64_t i = 0; i < n; ++i)
              ASSERT_EQ(got[i], expected[i]) << "AO, tier " << int(tier) << " levels " << levels
                                             << " half " << half << " point " << i;
            for (const auto& light : lights)
            {
              ASSERT_TRUE(vao::surfaceShadow(
                whole, points.data(), normals.data(), n, light, p, expected.data())
                            .ok);
              vao::SurfacePyramid fresh = surfacePyramidOf(f, pp);
              ASSERT_TRUE(
                vao::surfaceShadow(fresh, points.data(), normals.data(), n, light, p, got.data())
                  .ok);
              for (std::int64_t i = 0; i < n; ++i)
                ASSERT_EQ(got[i], expected[i])
                  << "shadow, tier " << int(tier) << " levels " << levels << " half " << half
                  << " light " << light[0] << " " << light[1] << " " << light[2] << " point " << i;
            }
            // A query of fewer levels than the pyramid has: its march stays longer on the
            // tiled levels (on level 0 alone to the volume's border with one level).
            for (int used = 1; used < levels; ++used)
            {
              p.levels = used;
              ASSERT_TRUE(vao::surfaceAmbientOcclusion(whole, f.view(), f.origin, f.spacing,
                points.data(), normals.data(), n, p, expected.data())
                            .ok);
              vao::SurfacePyramid fresh = surfacePyramidOf(f, pp);
              ASSERT_TRUE(vao::surfaceAmbientOcclusion(fresh, f.view(), f.origin, f.spacing,
                points.data(), normals.data(), n, p, got.data())
                            .ok);
              ASSERT_EQ(got, expected)
                << "AO of " << used << " levels, tier " << int(tier) << " pyramid " << levels;
              ASSERT_TRUE(vao::surfaceShadow(
                whole, points.data(), normals.data(), n, lights[0], p, expected.data())
                            .ok);
              ASSERT_TRUE(vao::surfaceShadow(
                fresh, points.data(), normals.data(), n, lights[0], p, got.data())
                            .ok);
              ASSERT_EQ(got, expected)
                << "shadow of " << used << " levels, tier " << int(tier) << " pyramid " << levels;
            }
          });
      }
  }
  vao::detail::limitSimdTier(vao::detail::SimdTier::Avx512);
}

TEST(SurfacePyramid, BuildsOnlyTheTilesASurfaceReachesAndKeepsThem)
{
  // A small sphere in a large volume: AO and a shadow reach a few of level 0's tiles; a
  // second query of the same kind builds nothing more, another light only what it adds.
  const vao::Index3 d = { 96, 96, 96 };
  const Vec3 c = { 48.3, 47.6, 48.1 };
  const Field f = makeField(d,
    [&](double x, double y, double z)
    {
      return std::sqrt(
               (x - c[0]) * (x - c[0]) + (y - c[1]) * (y - c[1]) + (z - c[2]) * (z - c[2])) -
        9.0;
    });
  std::vector<double> points, normals;
  spherePoints(c, 9.0, 2000, points, normals);
  const std::int64_t n = static_cast<std::int64_t>(points.size() / 3);
  vao::PyramidParameters pp;
  vao::SurfacePyramid surface = surfacePyramidOf(f, pp);
  EXPECT_EQ(surface.tileCount(0), 12 * 12 * 12);
  EXPECT_EQ(surface.tileCount(1), 6 * 6 * 6);
  EXPECT_EQ(surface.tileCount(2), 0); // whole
  EXPECT_EQ(surface.builtTiles(0) + surface.builtTiles(1), 0);
  std::vector<float> out(n);
  ASSERT_TRUE(vao::surfaceAmbientOcclusion(
    surface, f.view(), f.origin, f.spacing, points.data(), normals.data(), n, {}, out.data())
                .ok);
  const std::int64_t afterAo = surface.builtTiles(0);
  EXPECT_GT(afterAo, 0);
  EXPECT_GT(surface.builtTiles(1), 0);
  EXPECT_LE(
    afterAo, 4 * 4 * 4); // the AO samples lie on a sphere of radius 11 voxels: 4 tiles a side
  ASSERT_TRUE(vao::surfaceAmbientOcclusion(
    surface, f.view(), f.origin, f.spacing, points.data(), normals.data(), n, {}, out.data())
                .ok);
  EXPECT_EQ(surface.builtTiles(0), afterAo);
  ASSERT_TRUE(
    vao::surfaceShadow(surface, points.data(), normals.data(), n, { 0, 0, 1 }, {}, out.data()).ok);
  const std::int64_t afterShadow = surface.builtTiles(0);
  EXPECT_GE(afterShadow, afterAo);
  EXPECT_LT(afterShadow, surface.tileCount(0) / 10);
  EXPECT_LT(surface.builtTiles(1), surface.tileCount(1) / 2);
}

TEST(SurfacePyramid, SweepsInSlabsHoldingLittleMoreThanItKeeps)
{
  // A tall volume (12 layers of level-0 tiles) whose surface spans it. Unlimited, a query
  // holds every tile its points reach at the end; with nothing kept, it holds at most
  // the tiles near one slab at any moment (watched from the progress reports, made on
  // the calling thread between a slab's loops) and the same results bit for bit; with
  // half kept, it ends with at most that, and the next query finds them built and
  // builds fewer tiles than a fresh one.
  const Field f = shellScene({ 30, 28, 90 });
  std::vector<double> points, normals;
  scenePoints(f, points, normals);
  const Vec3 c = { f.origin[0] + 15 * f.spacing[0], f.origin[1] + 14 * f.spacing[1],
    f.origin[2] + 45 * f.spacing[2] };
  // A tall cylinder of points through the scene.
  for (int i = 0; i < 4000; ++i)
  {
    const double angle = 0.37 * i, height = (i % 400) / 400.0 * 86 * f.spacing[2];
    points.insert(points.end(),
      { c[0] + 6 * std::cos(angle), c[1] + 6 * std::sin(angle), f.origin[2] + height });
    normals.insert(normals.end(), { std::cos(angle), std::sin(angle), 0.1 });
  }
  const std::int64_t n = static_cast<std::int64_t>(points.size() / 3);
  vao::PyramidParameters pp;
  std::vector<float> expectedAo, expectedShadow, ao(n, -1.0f), shadow(n, -1.0f);
  const std::array<double, 3> light = { 0.3, -0.2, 1.0 };
  wholePyramidAnswers(f, points, normals, light, expectedAo, expectedShadow);
  auto held = [](const vao::SurfacePyramid& s) { return s.builtTiles(0) + s.builtTiles(1); };
  auto made = [](vao::SurfacePyramid& s)
  {
    const auto& tiles = *vao::SurfacePyramidAccess::tiles(s);
    return tiles.at(0)->madeTiles() + tiles.at(1)->madeTiles();
  };

  vao::SurfacePyramid unlimited = surfacePyramidOf(f, pp);
  unlimited.setKeptTileBytes(static_cast<std::size_t>(-1));
  ASSERT_TRUE(vao::surfaceAmbientOcclusion(
    unlimited, f.view(), f.origin, f.spacing, points.data(), normals.data(), n, {}, ao.data())
                .ok);
  ASSERT_TRUE(
    vao::surfaceShadow(unlimited, points.data(), normals.data(), n, light, {}, shadow.data()).ok);
  const std::int64_t reached = held(unlimited);
  EXPECT_EQ(made(unlimited), reached);
  ASSERT_EQ(unlimited.tileCount(0), 4 * 4 * 12);
  EXPECT_GT(unlimited.builtTiles(0), 4 * 4 * 10 / 2) << "the surface reaches most layers";
  EXPECT_EQ(ao, expectedAo);
  EXPECT_EQ(shadow, expectedShadow);

  vao::SurfacePyramid streamed = surfacePyramidOf(f, pp);
  streamed.setKeptTileBytes(0);
  std::int64_t peak = 0;
  vao::Execution watched;
  watched.progress = [&](double) { peak = std::max(peak, held(streamed)); };
  std::fill(ao.begin(), ao.end(), -1.0f);
  std::fill(shadow.begin(), shadow.end(), -1.0f);
  ASSERT_TRUE(vao::surfaceAmbientOcclusion(streamed, f.view(), f.origin, f.spacing, points.data(),
    normals.data(), n, {}, ao.data(), watched)
                .ok);
  ASSERT_TRUE(vao::surfaceShadow(
    streamed, points.data(), normals.data(), n, light, {}, shadow.data(), watched)
                .ok);
  EXPECT_EQ(ao, expectedAo);
  EXPECT_EQ(shadow, expectedShadow);
  EXPECT_GT(peak, 0);
  EXPECT_LT(peak, reached / 2) << "held " << peak << " of the " << reached << " tiles reached";
  EXPECT_LT(held(streamed), reached / 2);

  vao::SurfacePyramid half = surfacePyramidOf(f, pp);
  const std::size_t kept = static_cast<std::size_t>(reached / 2) * vao::PyramidTiles::kTileBytes;
  half.setKeptTileBytes(kept);
  EXPECT_EQ(half.keptTileBytes(), kept);
  ASSERT_TRUE(
    vao::surfaceShadow(half, points.data(), normals.data(), n, light, {}, shadow.data()).ok);
  EXPECT_EQ(shadow, expectedShadow);
  EXPECT_LE(static_cast<std::size_t>(held(half)) * vao::PyramidTiles::kTileBytes, kept);
  const std::int64_t first = made(half);
  ASSERT_TRUE(
    vao::surfaceShadow(half, points.data(), normals.data(), n, light, {}, shadow.data()).ok);
  EXPECT_EQ(shadow, expectedShadow);
  EXPECT_LT(made(half) - first, first * 3 / 4) << "the second query finds the tiles the first kept";
}

TEST(SurfacePyramid, AQueryAfterAnAbortedOneLosesNothing)
{
  // An AO query aborted at each of its checks in turn leaves tiles marked (some with a
  // slot taken), built or in use. The next, complete query (the AO again, or a shadow of
  // the sphere's points alone, whose slabs miss the layers of most others) gives the
  // whole pyramid's results. With every tile kept, each slot taken holds a built tile (a
  // marked tile's slot taken again would be lost); with none kept, it ends holding none
  // (a tile left in use would never be released).
  const Field f = shellScene({ 30, 28, 90 });
  std::vector<double> points, normals;
  scenePoints(f, points, normals);
  const std::int64_t n = static_cast<std::int64_t>(points.size() / 3);
  vao::PyramidParameters pp;
  const std::int64_t sphere = n - 150; // scenePoints: the sphere's, then 150 anywhere
  std::vector<float> expectedAo, expectedShadow, got(n);
  const std::array<double, 3> light = { 0.3, -0.2, 1.0 };
  wholePyramidAnswers(f, points, normals, light, expectedAo, expectedShadow);
  for (std::size_t kept : { static_cast<std::size_t>(-1), std::size_t(0) })
  {
    int aborted = 0;
    for (int checks = 0; checks < 1000; ++checks)
    {
      vao::SurfacePyramid surface = surfacePyramidOf(f, pp);
      surface.setKeptTileBytes(kept);
      int calls = 0;
      vao::Execution abort;
      abort.threads = 2;
      abort.abortRequested = [&] { return ++calls > checks; };
      if (vao::surfaceAmbientOcclusion(surface, f.view(), f.origin, f.spacing, points.data(),
            normals.data(), n, {}, got.data(), abort)
            .ok)
        break;
      ++aborted;
      for (bool shadow : { false, true })
      {
        vao::SurfacePyramid again = surfacePyramidOf(f, pp);
        again.setKeptTileBytes(kept);
        calls = 0;
        ASSERT_FALSE(vao::surfaceAmbientOcclusion(again, f.view(), f.origin, f.spacing,
          points.data(), normals.data(), n, {}, got.data(), abort)
                       .ok);
        std::fill(got.begin(), got.end(), -1.0f);
        const std::int64_t m = shadow ? sphere : n;
        ASSERT_TRUE(shadow
            ? vao::surfaceShadow(again, points.data(), normals.data(), m, light, {}, got.data()).ok
            : vao::surfaceAmbientOcclusion(again, f.view(), f.origin, f.spacing, points.data(),
                normals.data(), m, {}, got.data())
                .ok);
        const std::vector<float>& expected = shadow ? expectedShadow : expectedAo;
        ASSERT_TRUE(std::equal(got.begin(), got.begin() + m, expected.begin()))
          << "after an abort at check " << checks;
        const std::int64_t held = again.builtTiles(0) + again.builtTiles(1);
        if (kept == 0)
          ASSERT_EQ(held, 0) << "after an abort at check " << checks << ", shadow " << shadow;
        else
          ASSERT_EQ(vao::SurfacePyramidAccess::tiles(again)->pool->taken(), held)
            << "after an abort at check " << checks << ", shadow " << shadow;
      }
    }
    EXPECT_GT(aborted, 10);
  }
}

TEST(SurfacePyramid, BadInputFailsWithMessage)
{
  vao::SurfacePyramid empty;
  const double p[3] = { 1, 1, 1 }, nrm[3] = { 0, 0, 1 };
  float out = 0;
  const Field f = shellScene({ 12, 12, 12 });
  vao::Status s =
    vao::surfaceAmbientOcclusion(empty, f.view(), f.origin, f.spacing, p, nrm, 1, {}, &out);
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("empty"), std::string::npos) << s.message;
  s = vao::surfaceShadow(empty, p, nrm, 1, { 0, 0, 1 }, {}, &out);
  EXPECT_FALSE(s.ok);
  vao::SurfacePyramid pyramid;
  vao::PyramidParameters pp;
  pp.levels = 17;
  s = vao::buildSurfacePyramid(f.view(), f.origin, f.spacing, pp, pyramid);
  EXPECT_FALSE(s.ok);
  EXPECT_TRUE(pyramid.empty());
  Field nan = f;
  nan.values[5] = std::numeric_limits<float>::quiet_NaN();
  s = vao::buildSurfacePyramid(nan.view(), nan.origin, nan.spacing, {}, pyramid);
  EXPECT_FALSE(s.ok);
  EXPECT_TRUE(pyramid.empty());
}
