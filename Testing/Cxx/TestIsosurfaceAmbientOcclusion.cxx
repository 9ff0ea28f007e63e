// Variance Occlusion Map and Isosurface Ambient Occlusion filters: the pyramid as a
// multiblock, the cache, shadows, bad input, and Monte-Carlo AO on the CT head's bone.
#include "MonteCarloOcclusion.h"
#include "TestHelpers.h"

#include "vtkAmbientOcclusionPhantom.h"
#include "vtkIsosurfaceAmbientOcclusion.h"
#include "vtkVarianceOcclusionMap.h"

#include "vtkCellArray.h"
#include "vtkFloatArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkShortArray.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <random>

using namespace vaotest;

namespace
{

// Measured on 2374 points of the CT head phantom's 400 HU bone surface (4 levels,
// Chebyshev, max combination) against 128-ray Monte-Carlo AO over the pyramid's reach
// (64 mm): correlation 0.51, mean AO 0.80 vs 0.71. The variance bound is coarse (a
// lower bound per level, blurred statistics); the margin covers the Monte-Carlo noise.
constexpr double kMinimumBoneCorrelation = 0.40;

/// A slab of dense material (z in [zLo, zHi]) in air, n^3 voxels, spacing 1.
vtkSmartPointer<vtkImageData> Slab(int n, int zLo, int zHi)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(n, n, n);
  SetDensity(image, vtkNew<vtkShortArray>(),
    [&](int, int, int k) { return k >= zLo && k <= zHi ? 1000 : 0; });
  return image;
}

vtkSmartPointer<vtkPolyData> Contour(vtkImageData* volume, double iso)
{
  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputData(volume);
  contour->SetValue(0, iso);
  contour->ComputeNormalsOn();
  contour->Update();
  return contour->GetOutput();
}

/// A float copy of the volume with a NaN at voxel (i, j, k).
vtkSmartPointer<vtkImageData> WithNaN(vtkImageData* volume, int i, int j, int k)
{
  auto copy = vtkSmartPointer<vtkImageData>::New();
  copy->DeepCopy(volume);
  vtkNew<vtkFloatArray> values;
  values->DeepCopy(volume->GetPointData()->GetScalars());
  values->SetName("Density");
  int ijk[3] = { i, j, k };
  values->SetValue(copy->ComputePointId(ijk), std::nanf(""));
  copy->GetPointData()->SetScalars(values);
  return copy;
}

TEST(VarianceOcclusionMapFilter, RejectsBadInputWithAClearError)
{
  const auto run = [](vtkImageData* volume, int threads)
  {
    vtkNew<vtkVarianceOcclusionMap> map;
    vtkNew<MessageCatcher> catcher;
    catcher->Watch(map);
    map->SetInputData(volume);
    map->SetNumberOfThreads(threads);
    map->Update();
    EXPECT_EQ(map->GetOutput()->GetNumberOfBlocks(), 0u);
    return catcher->AllErrors();
  };
  auto volume = Slab(12, 4, 6);
  EXPECT_NE(run(volume, -1).find("NumberOfThreads"), std::string::npos);
  for (vtkIdType tuples : { 11, 1727, 1729 })
  {
    const std::string error =
      run(vtkImageData::SafeDownCast(WithPointArrayResized(volume, "Density", tuples)), 0);
    EXPECT_NE(error.find("Array 'Density' has " + std::to_string(tuples) +
                " tuples for the input's 1728 points"),
      std::string::npos)
      << error;
  }
  vtkNew<vtkImageData> shifted;
  shifted->DeepCopy(WithNaN(volume, 2, 9, 4));
  shifted->SetExtent(10, 21, -3, 8, 0, 11);
  const std::string error = run(shifted, 0);
  EXPECT_NE(
    error.find("has 1 NaN or infinite values (the first at voxel 12, 6, 4)"), std::string::npos)
    << error;
}

TEST(VarianceOcclusionMapFilter, OutputsOneImagePerLevelWithItsGeometry)
{
  vtkNew<vtkImageData> volume;
  volume->DeepCopy(Slab(33, 10, 14));
  volume->SetOrigin(-3.0, 2.0, 5.0);
  volume->SetSpacing(0.5, 0.75, 1.25);
  vtkNew<vtkVarianceOcclusionMap> map;
  map->SetInputData(volume);
  map->Update();
  vtkMultiBlockDataSet* pyramid = map->GetOutput();
  ASSERT_EQ(pyramid->GetNumberOfBlocks(), 4u);
  int expected = 33;
  for (unsigned l = 0; l < 4; ++l)
  {
    auto* level = vtkImageData::SafeDownCast(pyramid->GetBlock(l));
    ASSERT_NE(level, nullptr);
    EXPECT_EQ(level->GetDimensions()[0], expected);
    const double scale = std::pow(2.0, l);
    EXPECT_DOUBLE_EQ(level->GetSpacing()[0], 0.5 * scale);
    EXPECT_DOUBLE_EQ(level->GetSpacing()[2], 1.25 * scale);
    EXPECT_DOUBLE_EQ(level->GetOrigin()[0], -3.0);
    EXPECT_DOUBLE_EQ(level->GetOrigin()[2], 5.0);
    ASSERT_NE(vtkFloatArray::SafeDownCast(level->GetPointData()->GetArray("Mean")), nullptr);
    ASSERT_NE(vtkFloatArray::SafeDownCast(level->GetPointData()->GetArray("Variance")), nullptr);
    expected = (expected + 1) / 2;
  }
}

/// Value of `name` at global index (i, j, k) of a level image with any extent.
double LevelValue(vtkImageData* level, const char* name, int i, int j, int k)
{
  int ijk[3] = { i, j, k };
  const vtkIdType id = level->ComputePointId(ijk);
  return level->GetPointData()->GetArray(name)->GetTuple1(id);
}

TEST(VarianceOcclusionMapFilter, PiecesReadLessAndEqualTheWholePyramid)
{
  // Streamed (or distributed) pieces: each reads its extent grown by the pyramid's reach,
  // never the whole volume, and its level voxels equal the whole pyramid's.
  for (bool half : { false, true })
    for (int pieces : { 2, 3, 5 })
    {
      SCOPED_TRACE(
        std::string(half ? "half resolution, " : "") + std::to_string(pieces) + " pieces");
      vtkNew<vtkAmbientOcclusionPhantom> phantom;
      phantom->SetDimensions(45, 39, 161);
      vtkNew<vtkVarianceOcclusionMap> whole;
      whole->SetInputConnection(phantom->GetOutputPort());
      whole->SetStartAtHalfResolution(half);
      whole->Update();
      vtkNew<vtkMultiBlockDataSet> reference;
      reference->DeepCopy(whole->GetOutput());

      vtkNew<vtkVarianceOcclusionMap> map;
      map->SetInputConnection(phantom->GetOutputPort());
      map->SetStartAtHalfResolution(half);
      std::vector<std::vector<int>> covered(4);
      for (int p = 0; p < pieces; ++p)
      {
        map->UpdatePiece(p, pieces, 0);
        const int* read = vtkImageData::SafeDownCast(map->GetInputDataObject(0, 0))->GetExtent();
        EXPECT_LT((read[5] - read[4] + 1) * (read[3] - read[2] + 1), 39 * 161)
          << "piece " << p << " read it all";
        for (unsigned l = 0; l < 4; ++l)
        {
          auto* level = vtkImageData::SafeDownCast(map->GetOutput()->GetBlock(l));
          auto* full = vtkImageData::SafeDownCast(reference->GetBlock(l));
          ASSERT_NE(level, nullptr);
          covered[l].resize(full->GetNumberOfPoints());
          if (level->GetNumberOfPoints() == 0)
            continue;
          EXPECT_DOUBLE_EQ(level->GetSpacing()[2], full->GetSpacing()[2]);
          EXPECT_DOUBLE_EQ(level->GetOrigin()[2], full->GetOrigin()[2]);
          const int* e = level->GetExtent();
          for (int k = e[4]; k <= e[5]; ++k)
            for (int j = e[2]; j <= e[3]; ++j)
              for (int i = e[0]; i <= e[1]; ++i)
              {
                for (const char* name : { "Mean", "Variance" })
                {
                  const double want = LevelValue(full, name, i, j, k);
                  ASSERT_NEAR(
                    LevelValue(level, name, i, j, k), want, 1e-6 * std::max(1.0, std::abs(want)))
                    << name << " of level " << l << " at " << i << "," << j << "," << k
                    << ", piece " << p;
                }
                int ijk[3] = { i, j, k };
                covered[l][full->ComputePointId(ijk)] = 1;
              }
        }
      }
      for (unsigned l = 0; l < 4; ++l)
        EXPECT_EQ(
          std::count(covered[l].begin(), covered[l].end(), 1), static_cast<long>(covered[l].size()))
          << "level " << l << ": every voxel in some piece";
    }
}

struct ShadeRun
{
  vtkSmartPointer<vtkPolyData> output;
  std::vector<std::string> errors;
};

ShadeRun Shade(vtkPolyData* surface, vtkImageData* volume,
  const std::function<void(vtkIsosurfaceAmbientOcclusion*)>& configure)
{
  vtkNew<vtkIsosurfaceAmbientOcclusion> filter;
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(filter);
  filter->SetInputData(0, surface);
  filter->SetVolumeData(volume);
  configure(filter);
  filter->Update();
  return { filter->GetOutput(), catcher->Errors };
}

TEST(IsosurfaceAmbientOcclusionFilter, ThePyramidIsBuiltOnceWhileOnlyTheQueryChanges)
{
  auto volume = Slab(32, 8, 12);
  auto surface = Contour(volume, 500);
  vtkNew<vtkIsosurfaceAmbientOcclusion> filter;
  filter->SetInputData(0, surface);
  filter->SetVolumeData(volume);
  filter->Update();
  EXPECT_EQ(filter->GetNumberOfPyramidBuilds(), 1);
  filter->ComputeShadowsOn();
  filter->SetLightDirection(1, 0, 1);
  filter->Update();
  filter->SetCombine(vtkIsosurfaceAmbientOcclusion::COMBINE_MEAN);
  filter->SetEstimator(vtkIsosurfaceAmbientOcclusion::GAUSSIAN_CDF);
  filter->SetQueryMode(vtkIsosurfaceAmbientOcclusion::ISO_VALUE);
  filter->SetIsoValue(400);
  filter->SetOffsetFactor(1.5);
  filter->Update();
  filter->SetInputData(0, Contour(volume, 300)); // a new surface
  filter->Update();
  EXPECT_EQ(filter->GetNumberOfPyramidBuilds(), 1)
    << "the query alone must not rebuild the pyramid";
  ASSERT_NE(filter->GetOutput()->GetPointData()->GetArray("Shadow"), nullptr);
  filter->SetNumberOfLevels(3);
  filter->Update();
  EXPECT_EQ(filter->GetNumberOfPyramidBuilds(), 2);
  // A new shallow copy of the same volume (what ParaView hands the filter on every
  // update) is the same data: no rebuild.
  vtkNew<vtkImageData> copy;
  copy->ShallowCopy(volume);
  filter->SetVolumeData(copy);
  filter->SetLightDirection(0, 1, 1);
  filter->Update();
  EXPECT_EQ(filter->GetNumberOfPyramidBuilds(), 2)
    << "a shallow copy of the volume rebuilt the pyramid";
  // New values in the array (announced as VTK asks, array->Modified()) or a new grid do.
  copy->GetPointData()->GetScalars()->Modified();
  filter->Update();
  EXPECT_EQ(filter->GetNumberOfPyramidBuilds(), 3);
  copy->SetSpacing(1.0, 1.0, 1.5);
  filter->Update();
  EXPECT_EQ(filter->GetNumberOfPyramidBuilds(), 4);
  copy->SetOrigin(0.25, 0.0, 0.0);
  filter->Update();
  EXPECT_EQ(filter->GetNumberOfPyramidBuilds(), 5);
}

TEST(IsosurfaceAmbientOcclusionFilter, ALightMoveReusesTheAmbientOcclusionAndNothingElseDoes)
{
  auto volume = Slab(32, 8, 12);
  auto surface = Contour(volume, 500);
  vtkNew<vtkIsosurfaceAmbientOcclusion> filter;
  filter->SetInputData(0, surface);
  filter->SetVolumeData(volume);
  filter->ComputeShadowsOn();
  filter->SetLightDirection(0, 0, 1);
  filter->Update();
  auto array = [&](const char* name)
  { return filter->GetOutput()->GetPointData()->GetArray(name); };
  auto values = [&](const char* name) { return Values(array(name)); };
  vtkDataArray* first = array("AmbientOcclusion");
  const auto firstAo = values("AmbientOcclusion");
  const auto firstShadow = values("Shadow");
  filter->SetLightDirection(1, 0, -1);
  filter->Update();
  EXPECT_EQ(array("AmbientOcclusion"), first) << "the light does not change the AO: it is reused";
  EXPECT_NE(values("Shadow"), firstShadow);
  // Whatever the AO reads makes it new, equal to a fresh filter's.
  auto fresh = [&](vtkPolyData* s, double offset)
  {
    const ShadeRun run =
      Shade(s, volume, [&](vtkIsosurfaceAmbientOcclusion* f) { f->SetOffsetFactor(offset); });
    return Values(run.output->GetPointData()->GetArray("AmbientOcclusion"));
  };
  filter->SetOffsetFactor(2.5);
  filter->Update();
  EXPECT_NE(values("AmbientOcclusion"), firstAo);
  EXPECT_EQ(values("AmbientOcclusion"), fresh(surface, 2.5)) << "a new offset factor";
  vtkDataArray* points = surface->GetPoints()->GetData();
  for (vtkIdType i = 0; i < points->GetNumberOfTuples(); ++i)
    points->SetComponent(i, 2, points->GetComponent(i, 2) + 0.5); // moved in place, then announced
  points->Modified();
  filter->Update();
  EXPECT_EQ(values("AmbientOcclusion"), fresh(surface, 2.5)) << "moved points";
  auto other = Contour(volume, 300);
  filter->SetInputData(0, other);
  filter->Update();
  EXPECT_EQ(values("AmbientOcclusion"), fresh(other, 2.5)) << "a new surface";
  EXPECT_EQ(filter->GetNumberOfPyramidBuilds(), 1);
}

TEST(IsosurfaceAmbientOcclusionFilter, ShadowsFallBehindASlabAndFollowTheLight)
{
  auto volume = Slab(40, 18, 22);
  auto surface = Contour(volume, 500);
  auto meanShadow = [&](double lightZ, bool top)
  {
    const ShadeRun run = Shade(surface, volume,
      [lightZ](vtkIsosurfaceAmbientOcclusion* f)
      {
        f->ComputeShadowsOn();
        f->SetLightDirection(0, 0, lightZ);
      });
    EXPECT_TRUE(run.errors.empty());
    vtkDataArray* shadow = run.output->GetPointData()->GetArray("Shadow");
    double sum = 0;
    int count = 0;
    for (vtkIdType i = 0; i < run.output->GetNumberOfPoints(); ++i)
    {
      const double z = run.output->GetPoint(i)[2];
      const double x = run.output->GetPoint(i)[0], y = run.output->GetPoint(i)[1];
      if ((top ? z > 20 : z < 20) && x > 8 && x < 31 && y > 8 && y < 31) // away from the edges
      {
        sum += shadow->GetComponent(i, 0);
        ++count;
      }
    }
    return sum / count;
  };
  // Light from +z: the top face is lit, the bottom face is behind the slab.
  EXPECT_GT(meanShadow(1.0, true), meanShadow(1.0, false) + 0.3);
  // Reversed, the roles swap.
  EXPECT_GT(meanShadow(-1.0, false), meanShadow(-1.0, true) + 0.3);
}

void ExpectRejected(vtkPolyData* surface, vtkImageData* volume,
  const std::function<void(vtkIsosurfaceAmbientOcclusion*)>& configure, const std::string& words)
{
  const ShadeRun run = Shade(surface, volume, configure);
  ExpectRefused(run.errors, run.output, words);
}

TEST(IsosurfaceAmbientOcclusionFilter, RejectsBadInputWithAClearError)
{
  auto volume = Slab(24, 8, 12);
  auto surface = Contour(volume, 500);
  const auto none = [](vtkIsosurfaceAmbientOcclusion*) {};
  // A surface outside the volume.
  vtkNew<vtkPolyData> moved;
  moved->DeepCopy(surface);
  for (vtkIdType i = 0; i < moved->GetNumberOfPoints(); ++i)
  {
    double p[3];
    moved->GetPoint(i, p);
    p[0] += 100.0;
    moved->GetPoints()->SetPoint(i, p);
  }
  ExpectRejected(moved, volume, none, "outside the volume");
  // No normals, a constant volume (no gradient either) and no polygons: nothing says
  // which way the points face.
  vtkNew<vtkPolyData> bare;
  bare->DeepCopy(surface);
  bare->GetPointData()->Initialize();
  bare->SetPolys(vtkNew<vtkCellArray>());
  auto flat = Slab(24, 100, 100); // all air
  ExpectRejected(bare, flat, none, "has no normal, the volume's gradient is zero there");
  ExpectRejected(
    surface, volume,
    [](vtkIsosurfaceAmbientOcclusion* f)
    {
      f->ComputeShadowsOn();
      f->SetLightDirection(0, 0, 0);
    },
    "LightDirection");
  ExpectRejected(
    surface, volume, [](vtkIsosurfaceAmbientOcclusion* f) { f->SetNumberOfLevels(0); },
    "NumberOfLevels");
  ExpectRejected(
    surface, volume, [](vtkIsosurfaceAmbientOcclusion* f) { f->SetOffsetFactor(-1); },
    "OffsetFactor");
  ExpectRejected(
    surface, volume, [](vtkIsosurfaceAmbientOcclusion* f) { f->SetNumberOfThreads(-1); },
    "NumberOfThreads");
  ExpectRejected(
    surface, WithNaN(volume, 7, 5, 3), none, "NaN or infinite values (the first at voxel 7, 5, 3)");
  for (vtkIdType tuples : { 13, 13823, 13825 })
    ExpectRejected(surface,
      vtkImageData::SafeDownCast(WithPointArrayResized(volume, "Density", tuples)), none,
      "Array 'Density' has " + std::to_string(tuples) + " tuples for the input's 13824 points");
  vtkNew<vtkImageData> twoD;
  twoD->DeepCopy(Slab(24, 8, 12));
  twoD->SetDimensions(24, 576, 1);
  ExpectRejected(surface, twoD, none, "3-D volume");
}

/// Whether the ray from p along d meets material above `iso` within `reach` (marched in
/// half-voxel steps from one voxel out) before it leaves the volume.
bool Blocked(vtkImageData* volume, double iso, const double p[3], const double d[3], double reach)
{
  const double h = volume->GetSpacing()[0];
  double bounds[6];
  volume->GetBounds(bounds);
  for (double s = h; s <= reach; s += 0.5 * h)
  {
    const double q[3] = { p[0] + s * d[0], p[1] + s * d[1], p[2] + s * d[2] };
    if (q[0] < bounds[0] || q[0] > bounds[1] || q[1] < bounds[2] || q[1] > bounds[3] ||
      q[2] < bounds[4] || q[2] > bounds[5])
      return false;
    if (Trilinear(volume, q) > iso)
      return true;
  }
  return false;
}

TEST(IsosurfaceAmbientOcclusionFilter, FollowsMonteCarloAmbientOcclusionOnTheCtBoneSurface)
{
  auto ct = ReadMetaImage(DataFile("ct_head_phantom/ct_head_phantom_128x128x136_int16.mha"));
  const double iso = 400.0;
  auto bone = Contour(ct, iso);
  const ShadeRun run = Shade(bone, ct, [](vtkIsosurfaceAmbientOcclusion*) {});
  ASSERT_TRUE(run.errors.empty());
  vtkDataArray* ao = run.output->GetPointData()->GetArray("AmbientOcclusion");
  vtkDataArray* normals = bone->GetPointData()->GetNormals();
  ASSERT_TRUE(ao && normals);
  // The reach of the pyramid: level 3 (kernel radius 8 x 4 mm) sampled one radius out.
  const double reach = 2.0 * 8.0 * 2.0 * ct->GetSpacing()[2];
  std::mt19937 rng(2008);
  std::vector<double> penner, traced;
  for (vtkIdType i = 0; i < bone->GetNumberOfPoints(); i += 40)
  {
    double p[3], n[3];
    bone->GetPoint(i, p);
    normals->GetTuple(i, n);
    penner.push_back(ao->GetComponent(i, 0));
    traced.push_back(
      MonteCarloAO(n, 128, rng, [&](const double d[3]) { return Blocked(ct, iso, p, d, reach); }));
  }
  const Agreement agreement = AgreementOf(penner, traced);
  const double correlation = agreement.correlation, mp = agreement.meanEstimate,
               mt = agreement.meanReference;
  std::cout << penner.size() << " bone surface points: correlation " << correlation << ", mean AO "
            << mp << ", Monte Carlo (reach " << reach << " mm) " << mt << std::endl;
  EXPECT_GT(correlation, kMinimumBoneCorrelation);
}

} // namespace
