// Isosurface Ambient Occlusion reads float points and normals (what contours give) in
// place and converts any other type: both must give the same bits, and a normals array
// shorter than the points is refused, whichever its type. A few zero or non-finite
// normals (contours make them at saddles) take the volume's gradient, or their polygons'
// normal, instead of emptying the surface.
#include "TestHelpers.h"

#include "vtkAmbientOcclusionPhantom.h"
#include "vtkIsosurfaceAmbientOcclusion.h"

#include "vtkCellArray.h"
#include "vtkDoubleArray.h"
#include "vtkFloatArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

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

/// The surface with its normals replaced by `normals` (float, 3 a point).
vtkSmartPointer<vtkPolyData> WithNormals(vtkPolyData* surface, const std::vector<float>& normals)
{
  vtkNew<vtkFloatArray> array;
  array->SetName("Normals");
  array->SetNumberOfComponents(3);
  array->SetNumberOfTuples(static_cast<vtkIdType>(normals.size() / 3));
  std::copy(normals.begin(), normals.end(), array->GetPointer(0));
  auto copy = vtkSmartPointer<vtkPolyData>::New();
  copy->ShallowCopy(surface);
  vtkNew<vtkPointData> pd;
  pd->SetNormals(array);
  copy->GetPointData()->ShallowCopy(pd);
  return copy;
}

std::vector<float> NormalsOf(vtkPolyData* surface)
{
  vtkDataArray* given = surface->GetPointData()->GetNormals();
  std::vector<float> normals(static_cast<size_t>(3 * given->GetNumberOfTuples()));
  for (vtkIdType i = 0; i < given->GetNumberOfTuples(); ++i)
    for (int a = 0; a < 3; ++a)
      normals[3 * i + a] = static_cast<float>(given->GetComponent(i, a));
  return normals;
}

double MaxDifference(const std::vector<double>& a, const std::vector<double>& b)
{
  EXPECT_EQ(a.size(), b.size());
  double most = 0.0;
  for (size_t i = 0; i < a.size() && i < b.size(); ++i)
    most = std::max(most, std::isfinite(a[i]) ? std::abs(a[i] - b[i]) : 1.0);
  return most;
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

TEST(IsosurfacePoints, ZeroAndNonFiniteNormalsTakeTheVolumesGradient)
{
  const Bone bone = BoneOf(48, 48, 40);
  vtkPolyData* surface = bone.surface;
  const vtkIdType n = surface->GetNumberOfPoints();
  ASSERT_GT(n, 1000);
  const float nan = std::numeric_limits<float>::quiet_NaN();
  const float inf = std::numeric_limits<float>::infinity();
  const std::vector<std::array<float, 3>> bad = { { 0.f, 0.f, 0.f }, { 0.f, 0.f, 0.f },
    { -0.f, 0.f, 0.f }, { nan, 0.f, 1.f }, { inf, 0.f, 0.f } };
  std::vector<float> broken = NormalsOf(surface), reference = broken;
  for (size_t k = 0; k < bad.size(); ++k)
  {
    const vtkIdType i = (k + 1) * n / (bad.size() + 1);
    std::copy(bad[k].begin(), bad[k].end(), broken.begin() + 3 * i);
    // The reference: minus the central difference of the trilinear volume, one voxel
    // each side, made unit length.
    double p[3], g[3];
    surface->GetPoint(i, p);
    double length2 = 0.0;
    for (int a = 0; a < 3; ++a)
    {
      double forward[3] = { p[0], p[1], p[2] }, backward[3] = { p[0], p[1], p[2] };
      forward[a] += bone.volume->GetSpacing()[a];
      backward[a] -= bone.volume->GetSpacing()[a];
      g[a] = (Trilinear(bone.volume, forward) - Trilinear(bone.volume, backward)) /
        (2.0 * bone.volume->GetSpacing()[a]);
      length2 += g[a] * g[a];
    }
    ASSERT_GT(length2, 0.0);
    for (int a = 0; a < 3; ++a)
      reference[3 * i + a] = static_cast<float>(-g[a] / std::sqrt(length2));
  }

  vtkNew<vtkIsosurfaceAmbientOcclusion> filter;
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(filter);
  filter->SetInputData(0, WithNormals(surface, broken));
  filter->SetVolumeData(bone.volume);
  filter->ComputeShadowsOn();
  filter->SetLightDirection(0.3, -1.0, 0.8);
  filter->Update();
  EXPECT_TRUE(catcher->Errors.empty()) << catcher->AllErrors();
  ASSERT_EQ(catcher->Warnings.size(), 1u);
  EXPECT_NE(catcher->Warnings[0].find("5 of the surface's " + std::to_string(n) + " point normals"),
    std::string::npos)
    << catcher->Warnings[0];
  vtkPointData* pd = filter->GetOutput()->GetPointData();
  ASSERT_NE(pd->GetArray("AmbientOcclusion"), nullptr);
  ASSERT_NE(pd->GetArray("Shadow"), nullptr);

  const auto expected = Shaded(WithNormals(surface, reference), bone.volume);
  EXPECT_LT(MaxDifference(Values(pd->GetArray("AmbientOcclusion")), expected.first), 1e-5);
  EXPECT_LT(MaxDifference(Values(pd->GetArray("Shadow")), expected.second), 1e-5);
}

TEST(IsosurfacePoints, WhereTheGradientIsZeroTooThePolygonsGiveTheNormal)
{
  // A dense slab above z = 12 and a square of two triangles at z = 4, in the flat air
  // below it: the gradient is zero at its corners. One corner has a normal, pointing up
  // towards the slab; the others have none, and the square's winding faces down.
  vtkNew<vtkImageData> volume;
  volume->SetDimensions(24, 24, 24);
  volume->AllocateScalars(VTK_FLOAT, 1);
  auto* values = vtkFloatArray::SafeDownCast(volume->GetPointData()->GetScalars());
  for (vtkIdType id = 0; id < values->GetNumberOfTuples(); ++id)
    values->SetValue(id, id / (24 * 24) >= 12 ? 100.f : 0.f);
  vtkNew<vtkPoints> points;
  points->SetDataTypeToFloat();
  for (const auto& xy : { std::array<double, 2>{ 8, 8 }, { 8, 15 }, { 15, 15 }, { 15, 8 } })
    points->InsertNextPoint(xy[0], xy[1], 4.0);
  vtkNew<vtkCellArray> polys;
  const vtkIdType a[3] = { 0, 1, 2 }, b[3] = { 0, 2, 3 }; // clockwise seen from above
  polys->InsertNextCell(3, a);
  polys->InsertNextCell(3, b);
  vtkNew<vtkPolyData> square;
  square->SetPoints(points);
  square->SetPolys(polys);

  auto aoOf = [&](vtkPolyData* surface, MessageCatcher* catcher)
  {
    vtkNew<vtkIsosurfaceAmbientOcclusion> filter;
    if (catcher)
      catcher->Watch(filter);
    filter->SetInputData(0, surface);
    filter->SetVolumeData(volume);
    filter->SetQueryMode(vtkIsosurfaceAmbientOcclusion::ISO_VALUE);
    filter->SetIsoValue(50.0);
    filter->Update();
    vtkDataArray* ao = filter->GetOutput()->GetPointData()->GetArray("AmbientOcclusion");
    return ao ? Values(ao) : std::vector<double>();
  };
  const std::vector<float> up = { 0, 0, 1, 0, 0, 1, 0, 0, 1, 0, 0, 1 };
  const std::vector<float> down = { 0, 0, -1, 0, 0, -1, 0, 0, -1, 0, 0, -1 };
  const std::vector<float> oneUp = { 0, 0, 1, 0, 0, 0, 0, 0, 0, 0, 0, 0 };
  const auto facingUp = aoOf(WithNormals(square, up), nullptr);
  const auto facingDown = aoOf(WithNormals(square, down), nullptr);
  ASSERT_EQ(facingUp.size(), 4u);
  ASSERT_EQ(facingDown.size(), 4u);
  // Which way the corners face matters: the slab occludes only what faces it.
  ASSERT_GT(facingDown[1] - facingUp[1], 0.05) << facingDown[1] << " " << facingUp[1];

  vtkNew<MessageCatcher> catcher;
  const auto repaired = aoOf(WithNormals(square, oneUp), catcher);
  EXPECT_TRUE(catcher->Errors.empty()) << catcher->AllErrors();
  EXPECT_EQ(catcher->Warnings.size(), 1u);
  EXPECT_LT(MaxDifference(repaired, facingUp), 1e-6);

  // A lone point without a normal, a gradient or a polygon cannot be shaded.
  points->InsertNextPoint(12.0, 12.0, 4.0);
  square->Modified();
  std::vector<float> lone = oneUp;
  lone.insert(lone.end(), { 0.f, 0.f, 0.f });
  vtkNew<MessageCatcher> refused;
  EXPECT_TRUE(aoOf(WithNormals(square, lone), refused).empty());
  ASSERT_FALSE(refused->Errors.empty());
  EXPECT_NE(refused->Errors[0].find("Point 4 of the surface"), std::string::npos)
    << refused->Errors[0];
}
