// The ranges the filters cache on their float outputs (vtkAmbientOcclusionRanges): each
// equals what VTK computes itself on a copy of the same values that has no cache, for
// every component, the norm and the finite variants; Modified() still drops them.
#include "TestHelpers.h"

#include "vtkAmbientOcclusionPhantom.h"
#include "vtkIsosurfaceAmbientOcclusion.h"
#include "vtkOcclusionSweeping.h"
#include "vtkVarianceOcclusionMap.h"
#include "vtkVolumetricAmbientOcclusion.h"

#include "vtkDataSet.h"
#include "vtkFloatArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationInformationVectorKey.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <string>

namespace
{

/// A copy of the values in an array VTK knows nothing about yet.
vtkSmartPointer<vtkFloatArray> Uncached(vtkFloatArray* array)
{
  auto copy = vtkSmartPointer<vtkFloatArray>::New();
  copy->SetNumberOfComponents(array->GetNumberOfComponents());
  copy->SetNumberOfTuples(array->GetNumberOfTuples());
  std::copy(
    array->GetPointer(0), array->GetPointer(0) + array->GetNumberOfValues(), copy->GetPointer(0));
  return copy;
}

/// Every float point array of the output has cached ranges equal to VTK's own.
void ExpectCachedRangesOfVtk(vtkDataSet* output, int expectedArrays)
{
  vtkPointData* pd = output->GetPointData();
  int checked = 0;
  for (int i = 0; i < pd->GetNumberOfArrays(); ++i)
  {
    auto* array = vtkFloatArray::SafeDownCast(pd->GetArray(i));
    if (!array)
      continue;
    SCOPED_TRACE(array->GetName());
    ASSERT_GT(array->GetNumberOfTuples(), 0);
    EXPECT_TRUE(array->GetInformation()->Has(vtkAbstractArray::PER_COMPONENT()))
      << "no cached range";
    EXPECT_TRUE(array->GetInformation()->Has(vtkAbstractArray::PER_FINITE_COMPONENT()))
      << "no cached range";
    auto fresh = Uncached(array);
    ASSERT_FALSE(fresh->GetInformation()->Has(vtkAbstractArray::PER_COMPONENT()));
    const int components = array->GetNumberOfComponents();
    for (int c = components > 1 ? -1 : 0; c < components; ++c)
    {
      double cached[2], vtk[2], cachedFinite[2], vtkFinite[2];
      array->GetRange(cached, c);
      fresh->GetRange(vtk, c);
      array->GetFiniteRange(cachedFinite, c);
      fresh->GetFiniteRange(vtkFinite, c);
      EXPECT_EQ(cached[0], vtk[0]) << "component " << c;
      EXPECT_EQ(cached[1], vtk[1]) << "component " << c;
      EXPECT_EQ(cachedFinite[0], vtkFinite[0]) << "component " << c;
      EXPECT_EQ(cachedFinite[1], vtkFinite[1]) << "component " << c;
    }
    ++checked;
  }
  EXPECT_EQ(checked, expectedArrays);
}

vtkSmartPointer<vtkImageData> Phantom()
{
  vtkNew<vtkAmbientOcclusionPhantom> phantom;
  phantom->SetDimensions(31, 27, 33);
  phantom->Update();
  return phantom->GetOutput();
}

TEST(CachedRanges, SweepingOutputsIncludingTheEightOctantsEqualVtksRanges)
{
  auto input = Phantom();
  vtkNew<vtkOcclusionSweeping> filter;
  filter->SetInputData(input);
  filter->SetIsoValue(-300.0);
  filter->OutputOctantVisibilityOn();
  filter->Update();
  vtkImageData* output = filter->GetOutput();
  ASSERT_TRUE(output->GetPointData()->GetArray("OctantVisibility"));
  // SignedDistance, AmbientOcclusion, OctantVisibility (the phantom's density is int16).
  ExpectCachedRangesOfVtk(output, 3);
}

TEST(CachedRanges, VolumetricOutputsEqualVtksRangesAndModifiedDropsThem)
{
  auto input = Phantom();
  vtkNew<vtkVolumetricAmbientOcclusion> filter;
  filter->SetInputData(input);
  filter->SetRadius(3);
  filter->ComputeVarianceOn();
  filter->Update();
  vtkImageData* output = filter->GetOutput();
  ExpectCachedRangesOfVtk(output, 2);

  // A value changed afterwards: Modified() drops the cache, and VTK sees the new value.
  auto* ao = vtkFloatArray::SafeDownCast(output->GetPointData()->GetArray("AmbientOcclusion"));
  ASSERT_TRUE(ao);
  ao->SetValue(7, 41.0f);
  ao->Modified();
  double range[2];
  ao->GetRange(range, 0);
  EXPECT_EQ(range[1], 41.0);
}

// Chebyshev, the Gaussian CDF and CDF Reconstruction keep the openness's range as they
// write it (vao::OutputRange); the cache that comes from it must be VTK's too.
TEST(CachedRanges, RangesTheMomentMethodsKeepEqualVtksRanges)
{
  auto input = Phantom();
  for (const int method :
    { vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF, vtkVolumetricAmbientOcclusion::CHEBYSHEV,
      vtkVolumetricAmbientOcclusion::CDF_RECONSTRUCTION })
  {
    for (const bool variance : { false, true })
    {
      SCOPED_TRACE(method);
      vtkNew<vtkVolumetricAmbientOcclusion> filter;
      filter->SetInputData(input);
      filter->SetMethod(method);
      filter->SetRadius(3);
      filter->SetComputeVariance(variance);
      filter->SetBackend(vtkVolumetricAmbientOcclusion::BACKEND_CPU);
      filter->Update();
      ExpectCachedRangesOfVtk(filter->GetOutput(), variance ? 2 : 1);
    }
  }
}

// The pyramid's levels carry the ranges the build kept, whole or as one piece of two.
TEST(CachedRanges, PyramidLevelsEqualVtksRanges)
{
  auto input = Phantom();
  for (const int half : { 0, 1 })
    for (const int pieces : { 1, 2 })
    {
      SCOPED_TRACE(testing::Message() << "half " << half << ", pieces " << pieces);
      vtkNew<vtkVarianceOcclusionMap> filter;
      filter->SetInputData(input);
      filter->SetNumberOfLevels(3);
      filter->SetStartAtHalfResolution(half);
      filter->UpdatePiece(pieces - 1, pieces, 0);
      auto* output = vtkMultiBlockDataSet::SafeDownCast(filter->GetOutputDataObject(0));
      ASSERT_TRUE(output);
      ASSERT_EQ(output->GetNumberOfBlocks(), 3u);
      for (unsigned int l = 0; l < 3; ++l)
        ExpectCachedRangesOfVtk(vtkDataSet::SafeDownCast(output->GetBlock(l)), 2);
    }
}

TEST(CachedRanges, SurfaceArraysWithDistinctComponentsEqualVtksRanges)
{
  auto volume = Phantom();
  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputData(volume);
  contour->SetValue(0, -300.0);
  contour->ComputeNormalsOn();
  contour->Update();
  auto surface = vtkSmartPointer<vtkPolyData>::New();
  surface->ShallowCopy(contour->GetOutput());
  // Three components with ranges far apart, and negative values for the norm.
  vtkNew<vtkFloatArray> probe;
  probe->SetName("Probe");
  probe->SetNumberOfComponents(3);
  probe->SetNumberOfTuples(surface->GetNumberOfPoints());
  for (vtkIdType i = 0; i < surface->GetNumberOfPoints(); ++i)
  {
    const float u = static_cast<float>(i % 97) / 7.0f;
    probe->SetTuple3(i, -50.0f + u, 3.0f * u, 1000.0f - u * u);
  }
  surface->GetPointData()->AddArray(probe);
  ASSERT_GT(surface->GetNumberOfPoints(), 100);
  vtkNew<vtkIsosurfaceAmbientOcclusion> filter;
  filter->SetInputData(0, surface);
  filter->SetVolumeData(volume);
  filter->ComputeShadowsOn();
  filter->Update();
  // Normals and Probe passed through, AmbientOcclusion and Shadow new.
  ExpectCachedRangesOfVtk(filter->GetOutput(), 4);
}

} // namespace
