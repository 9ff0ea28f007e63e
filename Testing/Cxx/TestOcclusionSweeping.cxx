// The Occlusion Sweeping filter: outputs, pieces, bad input, an iso value off the data;
// the message of a kernel's shortage of memory, as its distributed run reports it.
#include "TestHelpers.h"

#include "vtkAmbientOcclusionArrayInput.h"
#include "vtkAmbientOcclusionPhantom.h"
#include "vtkOcclusionSweeping.h"

#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkShortArray.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <functional>

using namespace vaotest;

namespace
{

/// A ball of radius r voxels about the centre of an n^3 short image of spacing 0.5: 100
/// inside, 0 outside.
vtkSmartPointer<vtkImageData> CentredBall(int n, double r)
{
  const double c = 0.5 * (n - 1);
  auto image = Ball(vtkNew<vtkShortArray>(), { n, n, n }, { c, c, c }, r,
    [](bool inside, int, int, int) { return inside ? 100 : 0; });
  image->SetSpacing(0.5, 0.5, 0.5);
  return image;
}

struct SweepRun
{
  vtkSmartPointer<vtkImageData> output;
  std::vector<std::string> errors, warnings;
};

SweepRun Sweep(vtkImageData* input, const std::function<void(vtkOcclusionSweeping*)>& configure)
{
  vtkNew<vtkOcclusionSweeping> filter;
  vtkNew<MessageCatcher> catcher;
  catcher->Watch(filter);
  filter->SetInputData(input);
  filter->SetIsoValue(50);
  configure(filter);
  filter->Update();
  return { filter->GetOutput(), catcher->Errors, catcher->Warnings };
}

TEST(OcclusionSweepingFilter, OutputsDistanceOcclusionAndOctants)
{
  auto ball = CentredBall(25, 7.3);
  const SweepRun run = Sweep(ball, [](vtkOcclusionSweeping* f) { f->OutputOctantVisibilityOn(); });
  ASSERT_TRUE(run.errors.empty()) << run.errors[0];
  auto* distance =
    vtkFloatArray::SafeDownCast(run.output->GetPointData()->GetArray("SignedDistance"));
  auto* ao = vtkFloatArray::SafeDownCast(run.output->GetPointData()->GetArray("AmbientOcclusion"));
  auto* octants =
    vtkFloatArray::SafeDownCast(run.output->GetPointData()->GetArray("OctantVisibility"));
  ASSERT_TRUE(distance && ao && octants);
  EXPECT_EQ(octants->GetNumberOfComponents(), 8);
  ASSERT_NE(run.output->GetPointData()->GetArray("Density"), nullptr);
  const double c = 12.0;
  vtkIdType id = 0;
  for (int k = 0; k < 25; ++k)
    for (int j = 0; j < 25; ++j)
      for (int i = 0; i < 25; ++i, ++id)
      {
        const bool inside = ball->GetPointData()->GetScalars()->GetComponent(id, 0) > 50;
        ASSERT_EQ(distance->GetValue(id) < 0, inside) << i << "," << j << "," << k;
        const double exact =
          0.5 * (std::sqrt((i - c) * (i - c) + (j - c) * (j - c) + (k - c) * (k - c)) - 7.3);
        ASSERT_NEAR(distance->GetValue(id), exact, 0.5 * 1.5) << "world units, spacing 0.5";
        ASSERT_GE(ao->GetValue(id), 0.0f);
        ASSERT_LE(ao->GetValue(id), 1.0f);
      }
  // The centre of the ball sees no sky; a corner of the volume, far from it, nearly all.
  EXPECT_LT(ao->GetValue((12 * 25 + 12) * 25 + 12), 0.01);
  EXPECT_GT(ao->GetValue(0), 0.8);
}

TEST(OcclusionSweepingFilter, PiecesEqualTheWholeResult)
{
  vtkNew<vtkAmbientOcclusionPhantom> phantom;
  phantom->SetDimensions(36, 40, 32);
  vtkNew<vtkOcclusionSweeping> filter;
  filter->SetInputConnection(phantom->GetOutputPort());
  filter->SetIsoValue(400);
  filter->Update();
  vtkNew<vtkImageData> whole;
  whole->DeepCopy(filter->GetOutput());
  const auto wholeAO = Values(whole->GetPointData()->GetArray("AmbientOcclusion"));
  for (int piece = 0; piece < 3; ++piece)
  {
    filter->UpdatePiece(piece, 3, 0);
    vtkImageData* out = filter->GetOutput();
    EXPECT_LT(out->GetNumberOfPoints(), whole->GetNumberOfPoints());
    const int* e = out->GetExtent();
    const auto ao = Values(out->GetPointData()->GetArray("AmbientOcclusion"));
    vtkIdType id = 0;
    for (int k = e[4]; k <= e[5]; ++k)
      for (int j = e[2]; j <= e[3]; ++j)
        for (int i = e[0]; i <= e[1]; ++i, ++id)
          ASSERT_EQ(ao[id], wholeAO[(k * 40 + j) * 36 + i]);
  }
}

TEST(OcclusionSweepingFilter, AnIsoValueOffTheDataWarnsAndGivesAnOpenField)
{
  const SweepRun run =
    Sweep(CentredBall(9, 3), [](vtkOcclusionSweeping* f) { f->SetIsoValue(1000); });
  EXPECT_TRUE(run.errors.empty());
  ASSERT_EQ(run.warnings.size(), 1u);
  EXPECT_NE(run.warnings[0].find("does not cross"), std::string::npos);
  const auto ao = Values(run.output->GetPointData()->GetArray("AmbientOcclusion"));
  EXPECT_EQ(*std::min_element(ao.begin(), ao.end()), 1.0);
}

void ExpectRejected(vtkImageData* input,
  const std::function<void(vtkOcclusionSweeping*)>& configure, const std::string& words)
{
  const SweepRun run = Sweep(input, configure);
  ExpectRefused(run.errors, run.output, words);
}

TEST(OcclusionSweepingFilter, RejectsBadInputWithAClearError)
{
  const auto none = [](vtkOcclusionSweeping*) {};
  vtkNew<vtkImageData> noArray;
  noArray->SetDimensions(5, 5, 5);
  ExpectRejected(noArray, none, "No numeric point array");
  vtkNew<vtkImageData> flat;
  flat->DeepCopy(CentredBall(9, 3));
  flat->SetDimensions(9, 81, 1);
  ExpectRejected(flat, none, "needs a 3-D volume");
  for (vtkIdType tuples : { 7, 728, 730 })
    ExpectRejected(
      vtkImageData::SafeDownCast(WithPointArrayResized(CentredBall(9, 3), "Density", tuples)), none,
      "Array 'Density' has " + std::to_string(tuples) + " tuples for the input's 729 points");
  auto nan = CentredBall(9, 3);
  vtkNew<vtkFloatArray> values;
  values->DeepCopy(nan->GetPointData()->GetScalars());
  values->SetName("Density");
  values->SetValue(40, std::nanf(""));
  nan->GetPointData()->SetScalars(values);
  ExpectRejected(nan, none, "NaN");
  ExpectRejected(nan, none, "NaN or infinite values (the first at voxel 4, 4, 0)");
  ExpectRejected(
    CentredBall(9, 3), [](vtkOcclusionSweeping* f) { f->SetIsoValue(std::nan("")); }, "iso");
  ExpectRejected(
    CentredBall(9, 3), [](vtkOcclusionSweeping* f) { f->SetNumberOfIterations(0); }, "iteration");
  ExpectRejected(
    CentredBall(9, 3), [](vtkOcclusionSweeping* f) { f->SetGamma(0); }, "gamma");
  ExpectRejected(
    CentredBall(9, 3), [](vtkOcclusionSweeping* f) { f->SetOpacity(1.5); }, "opacity");
  ExpectRejected(
    CentredBall(9, 3), [](vtkOcclusionSweeping* f) { f->SetConvergenceTolerance(-1); },
    "tolerance");
  ExpectRejected(
    CentredBall(9, 3),
    [](vtkOcclusionSweeping* f)
    {
      int none8[8] = { 0, 0, 0, 0, 0, 0, 0, 0 };
      f->SetOctantMask(none8);
    },
    "octant");
  ExpectRejected(
    CentredBall(9, 3), [](vtkOcclusionSweeping* f) { f->SetNumberOfThreads(-1); },
    "NumberOfThreads");
}

} // namespace

TEST(OcclusionSweeping, AKernelShortageIsSaidAsTheFiltersOwn)
{
  // What the kernel names, or (its short message, when even that could not be had) the
  // working buffers; never an exception from reading the message.
  const vtkAmbientOcclusionArrayInput::ScalarVolume scalars;
  const std::string named = vtkAmbientOcclusionArrayInput::KernelError(
    vao::Status::noMemory("the sweeping buffers"), scalars, "Occlusion sweeping failed");
  EXPECT_EQ(named.find("Not enough memory for the sweeping buffers; "), 0u) << named;
  vao::Status bare = vao::Status::noMemory("x");
  bare.message = "out of memory";
  const std::string unnamed =
    vtkAmbientOcclusionArrayInput::KernelError(bare, scalars, "Occlusion sweeping failed");
  EXPECT_EQ(unnamed.find("Not enough memory for its working buffers; "), 0u) << unnamed;
}
