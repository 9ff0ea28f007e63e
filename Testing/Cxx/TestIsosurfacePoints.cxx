// Isosurface Ambient Occlusion reads float points and normals (what contours give) in
// place and converts any other type: both must give the same bits, and a normals array
// shorter than the points is refused, whichever its type.
#include "TestHelpers.h"

#include "vtkAmbientOcclusionPhantom.h"
#include "vtkIsosurfaceAmbientOcclusion.h"

#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <gtest/gtest.h>

using namespace vaotest;

namespace
{

/// The phantom's bone (400 HU): its volume and its contour, float points and normals.
struct Bone
{
  vtkSmartPointer<vtkImageData> volume;
  vtkSmartPointer<vtkPolyData> surface;
};

Bone BoneOf(int nx, int ny, int nz)
{
  vtkNew<vtkAmbientOcclusionPhantom> phantom;
  phantom->SetDimensions(nx, ny, nz);
  phantom->Update();
  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputData(phantom->GetOutput());
  contour->SetValue(0, 400.0);
  contour->ComputeNormalsOn();
  contour->Update();
  return { phantom->GetOutput(), contour->GetOutput() };
}

/// AO and shadows of `surface` on `volume` (one filter each, so nothing is cached).
std::pair<std::vector<double>, std::vector<double>> Shaded(
  vtkPolyData* surface, vtkImageData* volume)
{
  vtkNew<vtkIsosurfaceAmbientOcclusion> filter;
  filter->SetInputData(0, surface);
  filter->SetVolumeData(volume);
  filter->ComputeShadowsOn();
  filter->SetLightDirection(0.3, -1.0, 0.8);
  filter->Update();
  vtkPointData* pd = filter->GetOutput()->GetPointData();
  EXPECT_NE(pd->GetArray("AmbientOcclusion"), nullptr);
  EXPECT_NE(pd->GetArray("Shadow"), nullptr);
  if (!pd->GetArray("AmbientOcclusion") || !pd->GetArray("Shadow"))
    return {};
  return { Values(pd->GetArray("AmbientOcclusion")), Values(pd->GetArray("Shadow")) };
}

} // namespace

TEST(IsosurfacePoints, FloatPointsInPlaceEqualTheirDoubleCopies)
{
  const Bone bone = BoneOf(48, 48, 40);
  vtkImageData* volume = bone.volume;
  vtkPolyData* floats = bone.surface;
  ASSERT_TRUE(vtkFloatArray::SafeDownCast(floats->GetPoints()->GetData()));
  ASSERT_TRUE(vtkFloatArray::SafeDownCast(floats->GetPointData()->GetNormals()));
  ASSERT_GT(floats->GetNumberOfPoints(), 1000);

  // The same surface with double points and normals.
  vtkNew<vtkPolyData> doubles;
  doubles->ShallowCopy(floats);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToDouble();
  points->DeepCopy(floats->GetPoints());
  doubles->SetPoints(points);
  vtkNew<vtkDoubleArray> normals;
  normals->DeepCopy(floats->GetPointData()->GetNormals());
  normals->SetName("Normals");
  vtkNew<vtkPointData> pd;
  pd->SetNormals(normals);
  doubles->GetPointData()->ShallowCopy(pd);
  ASSERT_TRUE(vtkDoubleArray::SafeDownCast(doubles->GetPoints()->GetData()));

  const auto fromFloats = Shaded(floats, volume);
  const auto fromDoubles = Shaded(doubles, volume);
  ASSERT_EQ(fromFloats.first.size(), static_cast<size_t>(floats->GetNumberOfPoints()));
  EXPECT_EQ(fromFloats.first, fromDoubles.first) << "AmbientOcclusion";
  EXPECT_EQ(fromFloats.second, fromDoubles.second) << "Shadow";
  // Lit and shadowed, open and occluded points alike: the comparison covers every branch.
  const auto shadow = std::minmax_element(fromFloats.second.begin(), fromFloats.second.end());
  EXPECT_LT(*shadow.first, 0.5);
  EXPECT_GT(*shadow.second, 0.5);
}

TEST(IsosurfacePoints, NormalsShorterThanThePointsAreRefused)
{
  const Bone bone = BoneOf(32, 32, 28);
  vtkImageData* volume = bone.volume;
  vtkPolyData* surface = bone.surface;
  const vtkIdType n = surface->GetNumberOfPoints();
  ASSERT_GT(n, 100);
  for (bool asDouble : { false, true })
  {
    SCOPED_TRACE(asDouble ? "double normals" : "float normals");
    vtkSmartPointer<vtkDataArray> shortNormals;
    if (asDouble)
      shortNormals = vtkSmartPointer<vtkDoubleArray>::New();
    else
      shortNormals = vtkSmartPointer<vtkFloatArray>::New();
    shortNormals->DeepCopy(surface->GetPointData()->GetNormals());
    shortNormals->SetNumberOfTuples(n - 7); // a hand-made array that missed some points
    shortNormals->SetName("Normals");
    vtkNew<vtkPolyData> broken;
    broken->ShallowCopy(surface);
    vtkNew<vtkPointData> pd;
    pd->SetNormals(shortNormals);
    broken->GetPointData()->ShallowCopy(pd);

    vtkNew<vtkIsosurfaceAmbientOcclusion> filter;
    vtkNew<MessageCatcher> catcher;
    catcher->Watch(filter);
    filter->SetInputData(0, broken);
    filter->SetVolumeData(volume);
    filter->ComputeShadowsOn();
    filter->Update();
    ASSERT_FALSE(catcher->Errors.empty());
    EXPECT_NE(catcher->Errors[0].find("normals"), std::string::npos) << catcher->Errors[0];
    EXPECT_NE(catcher->Errors[0].find(
                std::to_string(n - 7) + " tuples for " + std::to_string(n) + " points"),
      std::string::npos)
      << catcher->Errors[0];
    EXPECT_EQ(filter->GetOutput()->GetNumberOfPoints(), 0);
  }
}
