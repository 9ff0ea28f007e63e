// The shading filter: Eq. 5 on volumes and surfaces, the variance modulation, bad input.
#include "TestHelpers.h"

#include "vtkAmbientOcclusionShading.h"

#include "vtkDataSet.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkUnsignedCharArray.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>

using namespace vaotest;

namespace
{

vtkSmartPointer<vtkFloatArray> Array(const char* name, std::vector<float> values)
{
  auto array = vtkSmartPointer<vtkFloatArray>::New();
  array->SetName(name);
  array->SetNumberOfTuples(static_cast<vtkIdType>(values.size()));
  for (size_t i = 0; i < values.size(); ++i)
    array->SetValue(static_cast<vtkIdType>(i), values[i]);
  return array;
}

/// A 2x2x2 volume: values 0..700 (step 100), AO 1, 0.5, 0.25, ..., variance 0..7000.
vtkSmartPointer<vtkImageData> SmallVolume()
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(2, 2, 2);
  image->GetPointData()->SetScalars(Array("Density", { 0, 100, 200, 300, 400, 500, 600, 700 }));
  image->GetPointData()->AddArray(
    Array("AmbientOcclusion", { 1, 0.5f, 0.25f, 1, 0.5f, 0.25f, 1, 0 }));
  image->GetPointData()->AddArray(
    Array("Variance", { 0, 1000, 2000, 3000, 4000, 5000, 6000, 7000 }));
  return image;
}

TEST(AmbientOcclusionShadingFilter, VolumesGetRuizEquation5AndTheVarianceModulation)
{
  auto volume = SmallVolume();
  vtkNew<vtkAmbientOcclusionShading> shading;
  shading->SetInputData(volume);
  shading->SetAmbientIntensity(0.8);
  shading->ModulateOpacityOn();
  shading->SetVarianceMax(4000);
  vtkNew<vtkPiecewiseFunction> opacity; // constant 1: only the modulation shows
  opacity->AddPoint(0, 1.0);
  opacity->AddPoint(700, 1.0);
  shading->SetOpacityTransferFunction(opacity);
  shading->Update();
  auto* rgba = vtkUnsignedCharArray::SafeDownCast(
    vtkDataSet::SafeDownCast(shading->GetOutput())->GetPointData()->GetArray("ShadedRGBA"));
  ASSERT_NE(rgba, nullptr);
  ASSERT_EQ(rgba->GetNumberOfComponents(), 4);
  for (vtkIdType i = 0; i < 8; ++i)
  {
    const double grey = i * 100.0 / 700.0; // the default grey-scale over the data range
    const double ao = volume->GetPointData()->GetArray("AmbientOcclusion")->GetComponent(i, 0);
    const double expected = std::min(1.0, 0.8 * ao * grey) * 255.0;
    EXPECT_NEAR(rgba->GetComponent(i, 0), expected, 1.0) << i;
    EXPECT_NEAR(rgba->GetComponent(i, 1), expected, 1.0) << i;
    const double m = std::min(1.0, i * 1000.0 / 4000.0);
    EXPECT_NEAR(rgba->GetComponent(i, 3), m * 255.0, 1.0) << i;
  }
  EXPECT_EQ(
    std::string(
      vtkDataSet::SafeDownCast(shading->GetOutput())->GetPointData()->GetScalars()->GetName()),
    "ShadedRGBA");
}

TEST(AmbientOcclusionShadingFilter, TheVarianceModulationIsClampedBelowFullOpacity)
{
  // At opacity 0.4 an unclamped modulation s2 / VarianceMax (up to 1.75 here) would show
  // as alpha above 0.4; at opacity 1 the byte conversion would hide it.
  vtkNew<vtkAmbientOcclusionShading> shading;
  shading->SetInputData(SmallVolume());
  shading->ModulateOpacityOn();
  shading->SetVarianceMax(4000);
  vtkNew<vtkPiecewiseFunction> opacity;
  opacity->AddPoint(0, 0.4);
  opacity->AddPoint(700, 0.4);
  shading->SetOpacityTransferFunction(opacity);
  shading->Update();
  vtkDataArray* rgba =
    vtkDataSet::SafeDownCast(shading->GetOutput())->GetPointData()->GetArray("ShadedRGBA");
  ASSERT_NE(rgba, nullptr);
  for (vtkIdType i = 0; i < 8; ++i)
    EXPECT_NEAR(rgba->GetComponent(i, 3), 0.4 * std::min(1.0, i * 1000.0 / 4000.0) * 255.0, 1.0)
      << i;
}

TEST(AmbientOcclusionShadingFilter, SurfacesGetColourTimesAmbientOcclusionTimesShadow)
{
  vtkNew<vtkPolyData> surface;
  vtkNew<vtkPoints> points;
  for (int i = 0; i < 4; ++i)
    points->InsertNextPoint(i, 0, 0);
  surface->SetPoints(points);
  surface->GetPointData()->AddArray(Array("AmbientOcclusion", { 1, 0.5f, 0.2f, 0 }));
  surface->GetPointData()->AddArray(Array("Shadow", { 1, 1, 0.5f, 1 }));
  vtkNew<vtkAmbientOcclusionShading> shading;
  shading->SetInputData(surface);
  shading->Update();
  vtkDataArray* rgb =
    vtkDataSet::SafeDownCast(shading->GetOutput())->GetPointData()->GetArray("ShadedRGB");
  ASSERT_NE(rgb, nullptr);
  const double expected[] = { 255, 127.5, 25.5, 0 }; // white x AO x shadow
  for (vtkIdType i = 0; i < 4; ++i)
    EXPECT_NEAR(rgb->GetComponent(i, 2), expected[i], 1.0) << i;
}

TEST(AmbientOcclusionShadingFilter, RejectsBadInputWithAClearError)
{
  auto check = [](vtkDataSet* input,
                 const std::function<void(vtkAmbientOcclusionShading*)>& configure,
                 const std::string& words)
  {
    vtkNew<vtkAmbientOcclusionShading> shading;
    vtkNew<MessageCatcher> catcher;
    catcher->Watch(shading);
    shading->SetInputData(input);
    configure(shading);
    shading->Update();
    ASSERT_FALSE(catcher->Errors.empty()) << words;
    EXPECT_NE(catcher->Errors[0].find(words), std::string::npos) << catcher->Errors[0];
    EXPECT_EQ(vtkDataSet::SafeDownCast(shading->GetOutput())->GetNumberOfPoints(), 0);
  };
  auto noAO = SmallVolume();
  noAO->GetPointData()->RemoveArray("AmbientOcclusion");
  check(
    noAO, [](vtkAmbientOcclusionShading*) {}, "AmbientOcclusion");
  auto noVariance = SmallVolume();
  noVariance->GetPointData()->RemoveArray("Variance");
  check(
    noVariance, [](vtkAmbientOcclusionShading* s) { s->ModulateOpacityOn(); }, "Variance");
  check(
    SmallVolume(), [](vtkAmbientOcclusionShading* s) { s->SetGamma(0); }, "Gamma");
  check(
    SmallVolume(), [](vtkAmbientOcclusionShading* s) { s->SetAmbientIntensity(-1); },
    "AmbientIntensity");
  check(
    SmallVolume(), [](vtkAmbientOcclusionShading* s) { s->SetColorPreset(7); }, "ColorPreset");
  check(
    SmallVolume(), [](vtkAmbientOcclusionShading* s) { s->SetScalarsArrayName("Nope"); }, "Nope");
  const double nan = std::numeric_limits<double>::quiet_NaN(),
               inf = std::numeric_limits<double>::infinity();
  check(
    SmallVolume(), [&](vtkAmbientOcclusionShading* s) { s->SetScalarRange(nan, 700); },
    "ScalarRange must be finite");
  check(
    SmallVolume(), [&](vtkAmbientOcclusionShading* s) { s->SetOpacityRamp(0, nan); },
    "OpacityRamp must be finite");
  auto infScalar = SmallVolume();
  infScalar->GetPointData()->GetScalars()->SetComponent(5, 0, inf);
  check(
    infScalar, [](vtkAmbientOcclusionShading*) {},
    "Array 'Density' has 1 NaN or infinite values (the first at point 5)");
  auto nanAO = SmallVolume();
  nanAO->GetPointData()->GetArray("AmbientOcclusion")->SetComponent(3, 0, nan);
  check(
    nanAO, [](vtkAmbientOcclusionShading*) {}, "Array 'AmbientOcclusion' has 1 NaN");
  auto nanVariance = SmallVolume();
  nanVariance->GetPointData()->GetArray("Variance")->SetComponent(2, 0, nan);
  check(
    nanVariance, [](vtkAmbientOcclusionShading* s) { s->ModulateOpacityOn(); },
    "Array 'Variance' has 1 NaN");
  check(
    SmallVolume(), [](vtkAmbientOcclusionShading* s) { s->SetNumberOfThreads(-2); },
    "NumberOfThreads");
  // An opacity transfer function (ParaView's, from the view) is checked as Volumetric AO
  // checks its own: an opacity outside [0, 1], a NaN point, no point at all.
  const auto withOpacity = [](double x, double y)
  {
    return [x, y](vtkAmbientOcclusionShading* s)
    {
      vtkNew<vtkPiecewiseFunction> opacity;
      opacity->AddPoint(-1000, 0.0);
      opacity->AddPoint(x, y);
      s->SetOpacityTransferFunction(opacity);
    };
  };
  check(SmallVolume(), withOpacity(500, 1.5),
    "OpacityTransferFunction: opacity point 1 has opacity 1.5");
  check(
    SmallVolume(), withOpacity(500, nan), "OpacityTransferFunction: opacity point 1 is not finite");
  check(
    SmallVolume(),
    [](vtkAmbientOcclusionShading* s)
    {
      vtkNew<vtkPiecewiseFunction> empty;
      s->SetOpacityTransferFunction(empty);
    },
    "OpacityTransferFunction: the opacity function has no points");
  // Arrays with fewer or more values than the points (read past their end before).
  const vtkIdType points = SmallVolume()->GetNumberOfPoints();
  for (const char* name : { "Density", "AmbientOcclusion", "Variance" })
    for (vtkIdType tuples : { vtkIdType(3), points - 1, points + 1 })
      check(
        WithPointArrayResized(SmallVolume(), name, tuples),
        [](vtkAmbientOcclusionShading* s) { s->ModulateOpacityOn(); },
        std::string("Array '") + name + "' has " + std::to_string(tuples) +
          " tuples for the input's " + std::to_string(points) + " points");
}

TEST(AmbientOcclusionShadingFilter, AnyNumberOfThreadsGivesTheSameColours)
{
  // A volume large enough for many chunks, shaded on 1, 2 and 5 threads.
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(61, 47, 33);
  const vtkIdType n = image->GetNumberOfPoints();
  std::vector<float> density(n), ao(n), variance(n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    density[i] = static_cast<float>((i * 7919) % 2600) - 1000.0f;
    ao[i] = static_cast<float>((i * 104729) % 1000) / 999.0f;
    variance[i] = static_cast<float>((i * 31) % 5000);
  }
  image->GetPointData()->SetScalars(Array("Density", density));
  image->GetPointData()->AddArray(Array("AmbientOcclusion", ao));
  image->GetPointData()->AddArray(Array("Variance", variance));
  std::vector<std::vector<unsigned char>> results;
  for (int threads : { 1, 2, 5 })
  {
    vtkNew<vtkAmbientOcclusionShading> shading;
    shading->SetInputData(image);
    shading->SetColorPreset(vtkAmbientOcclusionShading::BONE);
    shading->ModulateOpacityOn();
    shading->SetNumberOfThreads(threads);
    shading->Update();
    vtkDataArray* rgba =
      vtkDataSet::SafeDownCast(shading->GetOutput())->GetPointData()->GetArray("ShadedRGBA");
    ASSERT_NE(rgba, nullptr);
    ASSERT_EQ(rgba->GetNumberOfTuples(), n);
    const auto* bytes = static_cast<const unsigned char*>(rgba->GetVoidPointer(0));
    results.emplace_back(bytes, bytes + 4 * n);
  }
  EXPECT_EQ(results[0], results[1]);
  EXPECT_EQ(results[0], results[2]);
}

} // namespace
