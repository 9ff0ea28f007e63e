// surfaceOcclusionAndShadow: AO and shadows of the same points in one pass on a
// SurfacePyramid must be the numbers of the two separate queries on the whole pyramid, bit
// for bit, for either point type, and fail as cleanly as they do.
#include "PyramidTestSupport.h"

using namespace vaotest;

TEST(SurfaceOnePass, OcclusionAndShadowEqualTheTwoQueries)
{
  // The SurfacePyramid keeps no tiles: each slab releases what the last built, so a tile
  // that one query's marking missed would hold zeros when the other samples it.
  const Field f = shellScene({ 45, 38, 41 });
  std::vector<double> points, normals;
  scenePoints(f, points, normals);
  const std::vector<float> pointsF(points.begin(), points.end()),
    normalsF(normals.begin(), normals.end());
  const std::int64_t n = static_cast<std::int64_t>(points.size() / 3);
  std::vector<vao::MomentLevel> whole;
  ASSERT_TRUE(vao::buildMomentPyramid(f.view(), f.origin, f.spacing, {}, whole).ok);
  for (const std::array<double, 3>& light :
    { std::array<double, 3>{ 0.2, -0.5, 1 }, std::array<double, 3>{ -1, 0, 0 } })
    forEachSurfaceQuery(
      [&](const vao::SurfaceOcclusionParameters& p)
      {
        for (bool single : { false, true })
        {
          std::vector<float> ao(n), shadow(n);
          const vao::Status a = single
            ? vao::surfaceAmbientOcclusion(whole, f.view(), f.origin, f.spacing, pointsF.data(),
                normalsF.data(), n, p, ao.data())
            : vao::surfaceAmbientOcclusion(whole, f.view(), f.origin, f.spacing, points.data(),
                normals.data(), n, p, ao.data());
          const vao::Status b = single
            ? vao::surfaceShadow(whole, pointsF.data(), normalsF.data(), n, light, p, shadow.data())
            : vao::surfaceShadow(whole, points.data(), normals.data(), n, light, p, shadow.data());
          ASSERT_TRUE(a.ok && b.ok) << a.message << b.message;
          vao::SurfacePyramid surface = surfacePyramidOf(f, {});
          surface.setKeptTileBytes(0);
          std::vector<float> gotAo(n, -1.0f), gotShadow(n, -1.0f);
          const vao::Status s = single
            ? vao::surfaceOcclusionAndShadow(surface, f.view(), f.origin, f.spacing, pointsF.data(),
                normalsF.data(), n, light, p, gotAo.data(), gotShadow.data())
            : vao::surfaceOcclusionAndShadow(surface, f.view(), f.origin, f.spacing, points.data(),
                normals.data(), n, light, p, gotAo.data(), gotShadow.data());
          ASSERT_TRUE(s.ok) << s.message;
          EXPECT_EQ(gotAo, ao) << "float points " << single;
          EXPECT_EQ(gotShadow, shadow) << "float points " << single;
        }
      });
}

TEST(SurfaceOnePass, BadInputFailsBeforeAnythingIsWritten)
{
  const Field f = shellScene({ 20, 18, 21 });
  std::vector<double> points, normals;
  scenePoints(f, points, normals);
  const std::int64_t n = static_cast<std::int64_t>(points.size() / 3);
  vao::SurfacePyramid surface = surfacePyramidOf(f, {});
  std::vector<float> ao(n, -1.0f), shadow(n, -1.0f);
  vao::Status s = vao::surfaceOcclusionAndShadow(surface, f.view(), f.origin, f.spacing,
    points.data(), normals.data(), n, { 0, 0, 0 }, {}, ao.data(), shadow.data());
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("light"), std::string::npos) << s.message;
  normals[4] = std::numeric_limits<double>::quiet_NaN();
  s = vao::surfaceOcclusionAndShadow(surface, f.view(), f.origin, f.spacing, points.data(),
    normals.data(), n, { 0, 0, 1 }, {}, ao.data(), shadow.data());
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("normal"), std::string::npos) << s.message;
  EXPECT_EQ(ao, std::vector<float>(n, -1.0f));
  EXPECT_EQ(shadow, std::vector<float>(n, -1.0f));
  EXPECT_EQ(surface.builtTiles(0) + surface.builtTiles(1), 0);
  vao::SurfacePyramid empty;
  s = vao::surfaceOcclusionAndShadow(empty, f.view(), f.origin, f.spacing, points.data(),
    normals.data(), n, { 0, 0, 1 }, {}, ao.data(), shadow.data());
  EXPECT_FALSE(s.ok);
  EXPECT_NE(s.message.find("empty"), std::string::npos) << s.message;
}
