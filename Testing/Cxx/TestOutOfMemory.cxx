// Allocation failure in every filter: under an address-space limit a request too large
// for it gives a clear error and an empty output (no abort), and a second run of the same
// filter object on a small input succeeds. ctest runs each test in its own process, so
// the limit (setrlimit) binds that process only.
#include "TestHelpers.h"

#include "vtkAmbientOcclusionPhantom.h"
#include "vtkAmbientOcclusionShading.h"
#include "vtkContourFilter.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkIsosurfaceAmbientOcclusion.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkOcclusionSweeping.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkProbeOutsideSurface.h"
#include "vtkUnsignedCharArray.h"
#include "vtkVarianceOcclusionMap.h"
#include "vtkVolumetricAmbientOcclusion.h"

#include <gtest/gtest.h>

#include <sys/resource.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <string>

namespace
{

using vaotest::MessageCatcher;

/// Limits this process's address space to what it maps now plus `headroomMb`.
void LimitAddressSpace(double headroomMb)
{
  std::ifstream status("/proc/self/status");
  std::string key;
  double mapped = 0.0; // kB
  while (status >> key)
  {
    if (key == "VmSize:")
    {
      status >> mapped;
      break;
    }
  }
  ASSERT_GT(mapped, 0.0);
  rlimit limit;
  limit.rlim_cur = static_cast<rlim_t>((mapped + headroomMb * 1024.0) * 1024.0);
  limit.rlim_max = RLIM_INFINITY;
  ASSERT_EQ(setrlimit(RLIMIT_AS, &limit), 0);
}

/// A 2-valued ball of `n`^3 unsigned chars (small: it exists before the limit).
vtkSmartPointer<vtkImageData> TwoValuedBall(int n)
{
  const double c = n / 2.0;
  return vaotest::Ball(vtkNew<vtkUnsignedCharArray>(), { n, n, n }, { c, c, c }, n / 3.0,
    [](bool inside, int, int, int) { return inside ? 200 : 10; });
}

/// Runs the filter (configured by `set`, which gives it an input), expecting an error
/// that says memory and an empty output, then a small input that succeeds.
void ExpectShortageThenSuccess(vtkAlgorithm* filter, const std::function<void(bool large)>& set,
  const std::function<vtkIdType()>& outputPoints)
{
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(filter);
  set(true);
  filter->Update();
  ASSERT_FALSE(catcher->Errors.empty()) << "no error under the memory limit";
  EXPECT_NE(catcher->AllErrors().find("Not enough memory"), std::string::npos)
    << catcher->AllErrors();
  EXPECT_EQ(outputPoints(), 0);
  catcher->Errors.clear();
  set(false);
  filter->Update();
  EXPECT_TRUE(catcher->Errors.empty()) << catcher->AllErrors();
  EXPECT_GT(outputPoints(), 0) << "the second, small run must work";
}

TEST(OutOfMemory, PhantomSource)
{
  vtkNew<vtkAmbientOcclusionPhantom> phantom;
  LimitAddressSpace(300);
  ExpectShortageThenSuccess(
    phantom,
    [&](bool large)
    { large ? phantom->SetDimensions(2000, 2000, 2000) : phantom->SetDimensions(24, 24, 24); },
    [&] { return phantom->GetOutput()->GetNumberOfPoints(); });
  EXPECT_NE(phantom->GetOutput()->GetPointData()->GetArray("Density"), nullptr);
}

TEST(OutOfMemory, VolumetricAmbientOcclusion)
{
  const auto large = TwoValuedBall(400),
             small = TwoValuedBall(24); // 64 MB of input; 256 MB of output
  vtkNew<vtkVolumetricAmbientOcclusion> filter;
  filter->SetRadius(2);
  LimitAddressSpace(160);
  ExpectShortageThenSuccess(
    filter, [&](bool big) { filter->SetInputData(big ? large : small); },
    [&] { return filter->GetOutput()->GetNumberOfPoints(); });
}

TEST(OutOfMemory, VolumetricAmbientOcclusionSmoothedQuery)
{
  // The output (108 MB) fits; the smoothed query's own buffer, a double per voxel
  // (216 MB), does not: the kernel's shortage, not the output's.
  const auto large = TwoValuedBall(300), small = TwoValuedBall(24);
  vtkNew<vtkVolumetricAmbientOcclusion> filter;
  filter->SetRadius(2);
  filter->SetQueryMode(vtkVolumetricAmbientOcclusion::SMOOTHED_VALUE);
  LimitAddressSpace(160);
  ExpectShortageThenSuccess(
    filter, [&](bool big) { filter->SetInputData(big ? large : small); },
    [&] { return filter->GetOutput()->GetNumberOfPoints(); });
}

TEST(OutOfMemory, OcclusionSweeping)
{
  const auto large = TwoValuedBall(300),
             small = TwoValuedBall(24); // 27 MB of input; 4 B + 32 B a voxel more
  vtkNew<vtkOcclusionSweeping> filter;
  filter->SetIsoValue(100);
  filter->SetOutputOctantVisibility(true);
  LimitAddressSpace(400);
  ExpectShortageThenSuccess(
    filter, [&](bool big) { filter->SetInputData(big ? large : small); },
    [&] { return filter->GetOutput()->GetNumberOfPoints(); });
}

TEST(OutOfMemory, VarianceOcclusionMap)
{
  const auto large = TwoValuedBall(400), small = TwoValuedBall(24); // level 0 alone: 512 MB
  vtkNew<vtkVarianceOcclusionMap> filter;
  LimitAddressSpace(300);
  ExpectShortageThenSuccess(
    filter, [&](bool big) { filter->SetInputData(big ? large : small); },
    [&]
    {
      auto* blocks = filter->GetOutput();
      return blocks && blocks->GetNumberOfBlocks() > 0 ? vtkIdType(blocks->GetNumberOfBlocks())
                                                       : vtkIdType(0);
    });
}

TEST(OutOfMemory, IsosurfaceAmbientOcclusion)
{
  const auto large = TwoValuedBall(400), small = TwoValuedBall(24);
  vtkNew<vtkContourFilter> bigContour, smallContour;
  bigContour->SetInputData(TwoValuedBall(24)); // the surface itself is small; the pyramid is not
  bigContour->SetValue(0, 100);
  bigContour->Update();
  smallContour->SetInputData(small);
  smallContour->SetValue(0, 100);
  smallContour->Update();
  vtkNew<vtkIsosurfaceAmbientOcclusion> filter;
  filter->SetIsoValue(100);
  LimitAddressSpace(300);
  ExpectShortageThenSuccess(
    filter,
    [&](bool big)
    {
      filter->SetInputData(0, big ? bigContour->GetOutput() : smallContour->GetOutput());
      filter->SetInputData(1, big ? large : small);
    },
    [&] { return filter->GetOutput()->GetNumberOfPoints(); });
}

TEST(OutOfMemory, AmbientOcclusionShading)
{
  // The input carries an AmbientOcclusion array; the RGBA output needs 4 B a voxel more.
  auto withAo = [](int n)
  {
    auto image = TwoValuedBall(n);
    vtkNew<vtkFloatArray> ao;
    ao->SetName("AmbientOcclusion");
    ao->SetNumberOfTuples(image->GetNumberOfPoints());
    ao->FillValue(0.5f);
    image->GetPointData()->AddArray(ao);
    return image;
  };
  const auto large = withAo(400), small = withAo(24);
  vtkNew<vtkAmbientOcclusionShading> filter;
  LimitAddressSpace(150);
  ExpectShortageThenSuccess(
    filter, [&](bool big) { filter->SetInputData(big ? large : small); },
    [&] { return vtkDataSet::SafeDownCast(filter->GetOutputDataObject(0))->GetNumberOfPoints(); });
}

TEST(OutOfMemory, ProbeOutsideSurface)
{
  // 10 M surface points with normals (240 MB, made before the limit): the points sampled
  // on both sides of each for the vote (480 MB) and the samples do not fit; 500 points do.
  const auto surfaceOf = [](vtkIdType n)
  {
    auto surface = vtkSmartPointer<vtkPolyData>::New();
    vtkNew<vtkPoints> points;
    points->SetNumberOfPoints(n);
    vtkNew<vtkFloatArray> normals;
    normals->SetName("Normals");
    normals->SetNumberOfComponents(3);
    normals->SetNumberOfTuples(n);
    for (vtkIdType i = 0; i < n; ++i)
    {
      points->SetPoint(i, 4.0 + (i % 16), 4.0 + (i / 16) % 16, 4.0 + (i / 256) % 16);
      normals->SetTuple3(i, 0.0, 0.0, 1.0);
    }
    surface->SetPoints(points);
    surface->GetPointData()->SetNormals(normals);
    return surface;
  };
  const auto large = surfaceOf(10000000), small = surfaceOf(500);
  const auto volume = TwoValuedBall(24);
  vtkNew<vtkFloatArray> distance;
  distance->SetName("SignedDistance");
  distance->SetNumberOfTuples(volume->GetNumberOfPoints());
  for (vtkIdType i = 0; i < volume->GetNumberOfPoints(); ++i)
    distance->SetValue(i, static_cast<float>(i % 24));
  volume->GetPointData()->AddArray(distance);
  vtkNew<vtkProbeOutsideSurface> filter;
  filter->SetInputData(1, volume);
  LimitAddressSpace(150);
  ExpectShortageThenSuccess(
    filter, [&](bool big) { filter->SetInputData(0, big ? large : small); },
    [&] { return filter->GetOutput()->GetNumberOfPoints(); });
}

} // namespace
