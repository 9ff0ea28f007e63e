// The moment pyramid's float32 levels at the edges of magnitude, through the filters that
// build it (Variance Occlusion Map, Isosurface Ambient Occlusion): values spanning too
// little or too much are refused with a reason, values far from 0 against their spread
// get a warning (their means lose detail), ordinary values neither.
#include "TestHelpers.h"

#include "vtkIsosurfaceAmbientOcclusion.h"
#include "vtkVarianceOcclusionMap.h"

#include "vtkDoubleArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"

#include <gtest/gtest.h>

#include <string>

using namespace vaotest;

namespace
{

/// A ball of 1000 in 0 with a ripple of +-7, scaled by `scale` and shifted by `offset`.
vtkSmartPointer<vtkImageData> RippledBall(double scale, double offset)
{
  return Ball(vtkNew<vtkDoubleArray>(), { 24, 22, 20 }, { 11.5, 10.2, 9.7 }, 6.0,
    [=](bool inside, int i, int j, int k)
    {
      const double v = (inside ? 1000.0 : 0.0) + 7.0 * ((i * 7 + j * 3 + k * 5) % 3 - 1);
      return v * scale + offset;
    });
}

struct Messages
{
  std::string errors;
  std::vector<std::string> warnings;
  bool output = false;
};

Messages VarianceMap(vtkImageData* volume)
{
  vtkNew<vtkVarianceOcclusionMap> map;
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(map);
  map->SetInputData(volume);
  map->Update();
  return { catcher->AllErrors(), catcher->Warnings, map->GetOutput()->GetNumberOfBlocks() > 0 };
}

Messages SurfaceAO(vtkImageData* volume, vtkPolyData* surface)
{
  vtkNew<vtkIsosurfaceAmbientOcclusion> ao;
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(ao);
  ao->SetInputData(surface);
  ao->SetVolumeData(volume);
  ao->SetComputeShadows(true);
  ao->Update();
  return { catcher->AllErrors(), catcher->Warnings,
    ao->GetOutput()->GetPointData()->GetArray("AmbientOcclusion") != nullptr };
}

bool Warned(const Messages& m)
{
  for (const auto& w : m.warnings)
    if (w.find("Subtract an offset") != std::string::npos)
      return true;
  return false;
}

} // namespace

TEST(PyramidMagnitudes, RefusedSpansWarnedOffsetsAndQuietOrdinaryValues)
{
  auto unit = RippledBall(1.0, 0.0);
  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputData(unit);
  contour->SetValue(0, 500.0);
  contour->ComputeNormalsOn();
  contour->Update();
  vtkPolyData* surface = contour->GetOutput();
  ASSERT_GT(surface->GetNumberOfPoints(), 100);

  // Ordinary values, the same at an offset the float32 means still resolve, and in small units.
  for (auto volume : { unit, RippledBall(1.0, 1e5), RippledBall(1e-12, 0.0) })
    for (const Messages& m : { VarianceMap(volume), SurfaceAO(volume, surface) })
    {
      EXPECT_TRUE(m.output) << m.errors;
      EXPECT_FALSE(Warned(m));
    }
  // An offset of 1e7 against a spread of 1000: AO and Shadow 7e-3 off; the user is told.
  for (const Messages& m :
    { VarianceMap(RippledBall(1.0, 1e7)), SurfaceAO(RippledBall(1.0, 1e7), surface) })
  {
    EXPECT_TRUE(m.output) << m.errors;
    EXPECT_TRUE(Warned(m));
  }
  // Spans whose variances leave float32: refused with a reason, no output.
  for (const double scale : { 1e-25, 1e17 })
    for (const Messages& m :
      { VarianceMap(RippledBall(scale, 0.0)), SurfaceAO(RippledBall(scale, 0.0), surface) })
    {
      EXPECT_FALSE(m.output);
      EXPECT_NE(m.errors.find("rescale the data"), std::string::npos) << m.errors;
    }
}
