// Oriented images (a direction matrix D, VTK 9): index (i, j, k) lies at origin +
// D (spacing * index). The filters work along the image's axes, so a scene and the same
// scene rotated must give the same AO; surfaces, normals and the light come rotated, the
// pyramid's levels must lie where their voxels are, and a D that is not a rotation is
// refused.
#include "TestHelpers.h"

#include "vtkIsosurfaceAmbientOcclusion.h"
#include "vtkOcclusionSweeping.h"
#include "vtkVarianceOcclusionMap.h"
#include "vtkVolumetricAmbientOcclusion.h"

#include "vtkFloatArray.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"

#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <string>
#include <vector>

using namespace vaotest;

namespace
{

using Matrix = std::array<double, 9>; // row-major: physical = origin + D (spacing * index)

/// Rotation by `angle` about the unit axis (Rodrigues' formula), written out here rather
/// than taken from the filters' helper.
Matrix Rotation(std::array<double, 3> axis, double angle)
{
  const double norm = std::sqrt(axis[0] * axis[0] + axis[1] * axis[1] + axis[2] * axis[2]);
  for (double& a : axis)
    a /= norm;
  const double c = std::cos(angle), s = std::sin(angle), t = 1.0 - c;
  const double x = axis[0], y = axis[1], z = axis[2];
  return { t * x * x + c, t * x * y - s * z, t * x * z + s * y, t * x * y + s * z, t * y * y + c,
    t * y * z - s * x, t * x * z - s * y, t * y * z + s * x, t * z * z + c };
}

std::array<double, 3> Times(const Matrix& m, const double v[3])
{
  return { m[0] * v[0] + m[1] * v[1] + m[2] * v[2], m[3] * v[0] + m[4] * v[1] + m[5] * v[2],
    m[6] * v[0] + m[7] * v[1] + m[8] * v[2] };
}

/// A ball beside a wall in air, n^3 float voxels of anisotropic spacing; `flat`: the ball
/// alone, in air of exactly 0.
vtkSmartPointer<vtkImageData> Scene(
  int n, const Matrix* direction, const double origin[3], bool flat = false)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(n, n, n);
  image->SetSpacing(1.0, 0.75, 1.25);
  image->SetOrigin(origin[0], origin[1], origin[2]);
  if (direction)
    image->SetDirectionMatrix(direction->data());
  SetDensity(image, vtkNew<vtkFloatArray>(),
    [n, flat](int i, int j, int k)
    {
      const double ball =
        std::hypot(i - 0.4 * n, j - 0.5 * n, k - 0.5 * n) < 0.2 * n ? 1000.0 : 0.0;
      if (flat)
        return static_cast<float>(
          std::hypot(i - 0.7 * n, j - 0.7 * n, k - 0.5 * n) < 0.2 * n ? 1000.0 : 0.0);
      const double wall = i >= 3 * n / 4 && i < 3 * n / 4 + 3 ? 1000.0 : 0.0;
      return static_cast<float>(std::max(ball, wall) + (i * 7 + j * 3 + k) % 5);
    });
  return image;
}

struct Shaded
{
  vtkSmartPointer<vtkPolyData> surface; // the contour, in the physical frame
  vtkSmartPointer<vtkPolyData> output;
};

/// Isosurface AO of the contour of `contoured` (vtkFlyingEdges3D: points and normals in
/// its physical frame) on `volume`; `warnings` gets the filter's.
Shaded ShadeContour(vtkImageData* volume, const double light[3], vtkImageData* contoured = nullptr,
  std::vector<std::string>* warnings = nullptr)
{
  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputData(contoured ? contoured : volume);
  contour->SetValue(0, 500.0);
  contour->ComputeNormalsOn();
  contour->Update();
  vtkNew<vtkIsosurfaceAmbientOcclusion> ao;
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(ao);
  ao->SetInputData(0, contour->GetOutput());
  ao->SetInputData(1, volume);
  ao->SetNumberOfLevels(3);
  ao->ComputeShadowsOn();
  ao->SetLightDirection(light[0], light[1], light[2]);
  ao->Update();
  EXPECT_TRUE(catcher->Errors.empty()) << catcher->AllErrors();
  if (warnings)
    *warnings = catcher->Warnings;
  return { contour->GetOutput(), ao->GetOutput() };
}

} // namespace

TEST(OrientedImages, IsosurfaceAmbientOcclusionOfARotatedSceneIsTheScenesOwn)
{
  const double zero[3] = { 0.0, 0.0, 0.0 }, origin[3] = { -7.5, 3.25, 12.0 };
  const double light[3] = { 0.3, -0.5, 0.8 };
  struct Case
  {
    Matrix direction;
    const double* origin;
    double tolerance;  // a quarter turn about z at the origin 0 moves every float exactly
    bool flat = false; // a ball in exact air, where the points read along the axes agree too
  };
  for (const Case& c : { Case{ Rotation({ 0, 0, 1 }, 0.5 * M_PI), zero, 0.0 },
         Case{ Rotation({ 1, 2, 3 }, 0.7), origin, 2e-5 },
         Case{ Rotation({ -2, 1, 0.5 }, 2.5), origin, 2e-5 },
         Case{ Rotation({ 0.3, -1, 0.2 }, 0.02), origin, 2e-5 },
         Case{ Rotation({ 0, 0, 1 }, 0.7), origin, 2e-5, true } })
  {
    Matrix exact = c.direction;
    if (c.tolerance == 0.0)
      for (double& m : exact)
        m = std::round(m); // cos(pi / 2) is 6e-17, not 0
    auto plain = Scene(24, nullptr, c.origin, c.flat);
    auto turned = Scene(24, &exact, c.origin, c.flat);
    const Shaded a = ShadeContour(plain, light);
    const std::array<double, 3> turnedLight = Times(exact, light);
    std::vector<std::string> warnings;
    const Shaded b = ShadeContour(turned, turnedLight.data(), nullptr, &warnings);
    EXPECT_TRUE(warnings.empty()) << (warnings.empty() ? "" : warnings.front());
    const vtkIdType n = a.surface->GetNumberOfPoints();
    ASSERT_GT(n, 300);
    ASSERT_EQ(b.surface->GetNumberOfPoints(), n);
    ASSERT_EQ(b.output->GetNumberOfPoints(), n) << "the rotated scene was refused";
    // The contours are the same points, rotated about the origin.
    for (vtkIdType i = 0; i < n; i += 97)
    {
      double p[3], q[3], d[3];
      a.surface->GetPoint(i, p);
      b.surface->GetPoint(i, q);
      for (int k = 0; k < 3; ++k)
        d[k] = p[k] - c.origin[k];
      const std::array<double, 3> r = Times(exact, d);
      for (int k = 0; k < 3; ++k)
        ASSERT_NEAR(q[k], c.origin[k] + r[k], 1e-4) << "point " << i;
    }
    for (const char* name : { "AmbientOcclusion", "Shadow" })
    {
      const std::vector<double> expected = Values(a.output->GetPointData()->GetArray(name));
      const std::vector<double> got = Values(b.output->GetPointData()->GetArray(name));
      int off = 0;
      for (vtkIdType i = 0; i < n; ++i)
        off += !(std::abs(got[i] - expected[i]) <= c.tolerance);
      // Float points and normals rotated round differently: 2e-6 apart at most (measured).
      EXPECT_EQ(off, 0) << name << ": " << off << " of " << n << " points differ by more than "
                        << c.tolerance;
    }
  }
}

TEST(OrientedImages, ASurfaceLeftAlongTheImagesAxesIsRecognised)
{
  // vtkContourFilter and vtkSynchronizedTemplates3D of VTK 9.2 (ParaView 5.11's Contour)
  // ignore the direction matrix: their contour of the turned volume is the plain one's.
  const double origin[3] = { -7.5, 3.25, 12.0 }, light[3] = { 0.3, -0.5, 0.8 };
  for (double angle : { 0.02, 0.7 })
  {
    const Matrix direction = Rotation({ 1, 2, 3 }, angle);
    auto plain = Scene(24, nullptr, origin);
    auto turned = Scene(24, &direction, origin);
    std::vector<std::string> warnings, none;
    const Shaded a = ShadeContour(plain, light, nullptr, &none);
    const Shaded b = ShadeContour(turned, light, plain, &warnings);
    EXPECT_TRUE(none.empty());
    ASSERT_EQ(warnings.size(), 1u) << angle;
    EXPECT_NE(warnings[0].find("direction matrix ignored"), std::string::npos) << warnings[0];
    for (const char* name : { "AmbientOcclusion", "Shadow" })
      EXPECT_EQ(Values(b.output->GetPointData()->GetArray(name)),
        Values(a.output->GetPointData()->GetArray(name)))
        << name << " at angle " << angle;
  }
}

TEST(OrientedImages, PyramidLevelsLieWhereTheirVoxelsAre)
{
  const double origin[3] = { 4.0, -2.5, 1.0 };
  const Matrix direction = Rotation({ 1, -1, 2 }, 1.1);
  auto plain = Scene(19, nullptr, origin);
  auto turned = Scene(19, &direction, origin);
  turned->SetExtent(2, 20, -3, 15, 5, 23); // and not starting at index 0
  plain->SetExtent(2, 20, -3, 15, 5, 23);
  vtkNew<vtkVarianceOcclusionMap> a, b;
  a->SetInputData(plain);
  b->SetInputData(turned);
  a->Update();
  b->Update();
  ASSERT_EQ(b->GetOutput()->GetNumberOfBlocks(), 4u);
  int step = 1;
  for (unsigned l = 0; l < 4; ++l, step *= 2)
  {
    vtkImageData* level = vtkImageData::SafeDownCast(b->GetOutput()->GetBlock(l));
    vtkImageData* same = vtkImageData::SafeDownCast(a->GetOutput()->GetBlock(l));
    const int* e = level->GetExtent();
    for (int k = e[4]; k <= e[5]; ++k)
      for (int j = e[2]; j <= e[3]; ++j)
        for (int i = e[0]; i <= e[1]; ++i)
        {
          // Level voxel (i, j, k) is input voxel first + step * (i, j, k) of the level's extent.
          const double index[3] = { double(i), double(j), double(k) };
          const double input[3] = { 2.0 + step * (i - e[0]), -3.0 + step * (j - e[2]),
            5.0 + step * (k - e[4]) };
          double p[3], q[3];
          level->TransformContinuousIndexToPhysicalPoint(index, p);
          turned->TransformContinuousIndexToPhysicalPoint(input, q);
          for (int a3 = 0; a3 < 3; ++a3)
            ASSERT_NEAR(p[a3], q[a3], 1e-9)
              << "level " << l << " voxel " << i << " " << j << " " << k;
        }
    // The levels' values are the axis-aligned scene's, bit for bit.
    EXPECT_EQ(Values(level->GetPointData()->GetArray("Mean")),
      Values(same->GetPointData()->GetArray("Mean")));
  }
}

TEST(OrientedImages, ADirectionThatIsNotARotationIsRefused)
{
  const double origin[3] = { 0.0, 0.0, 0.0 };
  const Matrix shear = { 1.0, 0.3, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0 };
  const Matrix stretch = { 2.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0 };
  for (const Matrix& m : { shear, stretch })
  {
    auto image = Scene(12, &m, origin);
    auto refused = [&](vtkAlgorithm* filter)
    {
      vtkNew<MessageCatcher> catcher;
      catcher->Watch(filter);
      filter->Update();
      EXPECT_NE(catcher->AllErrors().find("is not a rotation"), std::string::npos)
        << catcher->AllErrors();
    };
    vtkNew<vtkVolumetricAmbientOcclusion> volumetric;
    volumetric->SetInputData(image);
    volumetric->SetRadius(2);
    refused(volumetric);
    EXPECT_EQ(volumetric->GetOutput()->GetNumberOfPoints(), 0);
    vtkNew<vtkOcclusionSweeping> sweeping;
    sweeping->SetInputData(image);
    sweeping->SetIsoValue(500);
    refused(sweeping);
    EXPECT_EQ(sweeping->GetOutput()->GetNumberOfPoints(), 0);
    vtkNew<vtkVarianceOcclusionMap> map;
    map->SetInputData(image);
    refused(map);
    vtkNew<vtkFlyingEdges3D> contour;
    contour->SetInputData(image);
    contour->SetValue(0, 500.0);
    contour->ComputeNormalsOn();
    vtkNew<vtkIsosurfaceAmbientOcclusion> surface;
    surface->SetInputConnection(0, contour->GetOutputPort());
    surface->SetInputData(1, image);
    refused(surface);
    EXPECT_EQ(surface->GetOutput()->GetNumberOfPoints(), 0);
  }
}
