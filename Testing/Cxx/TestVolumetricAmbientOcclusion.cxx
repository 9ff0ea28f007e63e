// The VTK filter: translation of VTK data into kernel calls, streaming, bad input.
#include "ReferenceFormulas.h"
#include "TestHelpers.h"
#include "VolumetricTestSupport.h"

#include "vtkAmbientOcclusionPhantom.h"
#include "vtkVolumetricAmbientOcclusion.h"

#include "vao/Cuda.h"
#include "vao/Estimators.h"

#include "vtkCallbackCommand.h"
#include "vtkCellData.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkShortArray.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"
#include "vtkTrivialProducer.h"

#include <gtest/gtest.h>

#include <array>

#include <cmath>
#include <random>

using namespace vaotest;

namespace
{

/// Brute-force openness of one voxel for the separable estimators, through the same
/// formulas (Estimators.h) on statistics computed here in long double.
double ReferenceOpenness(vtkImageData* image, int method, const int r[3], int i, int j, int k)
{
  const int* e = image->GetExtent();
  vtkDataArray* a = image->GetPointData()->GetScalars();
  auto value = [&](int x, int y, int z)
  {
    return a->GetComponent(
      ((z - e[4]) * (e[3] - e[2] + 1) + (y - e[2])) * (e[1] - e[0] + 1) + (x - e[0]), 0);
  };
  long double sum = 0, n = 0, lo = 1e300, hi = -1e300;
  for (int z = std::max(e[4], k - r[2]); z <= std::min(e[5], k + r[2]); ++z)
    for (int y = std::max(e[2], j - r[1]); y <= std::min(e[3], j + r[1]); ++y)
      for (int x = std::max(e[0], i - r[0]); x <= std::min(e[1], i + r[0]); ++x)
      {
        const double v = value(x, y, z);
        sum += v;
        n += 1;
        lo = std::min<long double>(lo, v);
        hi = std::max<long double>(hi, v);
      }
  const long double mean = sum / n;
  long double m2 = 0;
  for (int z = std::max(e[4], k - r[2]); z <= std::min(e[5], k + r[2]); ++z)
    for (int y = std::max(e[2], j - r[1]); y <= std::min(e[3], j + r[1]); ++y)
      for (int x = std::max(e[0], i - r[0]); x <= std::min(e[1], i + r[0]); ++x)
        m2 += (value(x, y, z) - mean) * (value(x, y, z) - mean);
  // docs/methods.md's formulas as the tests write them (CUDA/tests/ReferenceFormulas.h).
  const vaotest::reference::Statistics s{ double(mean), double(m2 / n), double(lo), double(hi) };
  const double q = value(i, j, k);
  switch (method)
  {
    case vtkVolumetricAmbientOcclusion::CDF_RECONSTRUCTION:
      return vaotest::reference::cdfReconstruction(q, s);
    case vtkVolumetricAmbientOcclusion::CHEBYSHEV:
      return vaotest::reference::chebyshev(q, s);
    default:
      return vaotest::reference::gaussianCdf(q, s, false);
  }
}

TEST(VolumetricAmbientOcclusion, MatchesBruteForceWithWorldRadiusOnAnOffsetExtent)
{
  auto image = RandomImage(13, 9, 15, 1);
  // Spacing 2, 1, 0.5: R = 4 is 2, 4, 8 voxels; R = 3 is 1.5, 3, 6, rounded to nearest: 2, 3, 6.
  for (const auto& [worldRadius, voxels] : { std::make_pair(4.0, std::array<int, 3>{ 2, 4, 8 }),
         std::make_pair(3.0, std::array<int, 3>{ 2, 3, 6 }) })
    for (int method : { vtkVolumetricAmbientOcclusion::CDF_RECONSTRUCTION,
           vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF, vtkVolumetricAmbientOcclusion::CHEBYSHEV })
    {
      const FilterRun run = RunFilter(image,
        [&](vtkVolumetricAmbientOcclusion* f)
        {
          f->SetMethod(method);
          f->SetRadiusUnits(vtkVolumetricAmbientOcclusion::WORLD);
          f->SetRadius(worldRadius);
          f->ComputeVarianceOn();
        });
      ASSERT_TRUE(run.errors.empty()) << run.errors[0];
      auto* ao =
        vtkFloatArray::SafeDownCast(run.output->GetPointData()->GetArray("AmbientOcclusion"));
      ASSERT_NE(ao, nullptr);
      ASSERT_NE(
        vtkFloatArray::SafeDownCast(run.output->GetPointData()->GetArray("Variance")), nullptr);
      ASSERT_NE(run.output->GetPointData()->GetArray("Density"), nullptr);
      EXPECT_EQ(std::string(run.output->GetPointData()->GetScalars()->GetName()), "Density");
      const int r[3] = { voxels[0], voxels[1], voxels[2] };
      const int* e = run.output->GetExtent();
      vtkIdType id = 0;
      for (int k = e[4]; k <= e[5]; ++k)
        for (int j = e[2]; j <= e[3]; ++j)
          for (int i = e[0]; i <= e[1]; ++i, ++id)
            ASSERT_NEAR(ao->GetValue(id), ReferenceOpenness(image, method, r, i, j, k), 2e-6)
              << "method " << method << " voxel " << i << "," << j << "," << k;
      auto* backend = vtkStringArray::SafeDownCast(
        run.output->GetFieldData()->GetAbstractArray("AmbientOcclusionBackend"));
      ASSERT_NE(backend, nullptr);
      EXPECT_EQ(backend->GetValue(0), "CPU");
      auto* device = vtkStringArray::SafeDownCast(
        run.output->GetFieldData()->GetAbstractArray("AmbientOcclusionDevice"));
      ASSERT_NE(device, nullptr);
      EXPECT_EQ(device->GetValue(0), "CPU");
    }
}

TEST(VolumetricAmbientOcclusion, ReadsTheChosenComponentOfAMultiComponentArray)
{
  auto single = RandomImage(9, 8, 7, 2);
  auto triple = RandomImage(9, 8, 7, 3, 3);
  auto* s = single->GetPointData()->GetScalars();
  auto* t = triple->GetPointData()->GetScalars();
  for (vtkIdType i = 0; i < s->GetNumberOfTuples(); ++i)
    t->SetComponent(i, 2, s->GetComponent(i, 0));
  const auto configure = [](int component)
  {
    return [component](vtkVolumetricAmbientOcclusion* f)
    {
      f->SetRadius(2);
      f->SetComponent(component);
    };
  };
  const FilterRun a = RunFilter(single, configure(-1));
  const FilterRun b = RunFilter(triple, configure(2));
  ASSERT_TRUE(a.errors.empty() && b.errors.empty());
  EXPECT_EQ(Values(a.output->GetPointData()->GetArray("AmbientOcclusion")),
    Values(b.output->GetPointData()->GetArray("AmbientOcclusion")));
}

TEST(VolumetricAmbientOcclusion, StreamedPiecesEqualTheOnePieceResult)
{
  // The phantom source produces exactly the extent it is asked for, so each piece only
  // sees its extent grown by the radius, as a rank of a distributed run does.
  vtkNew<vtkAmbientOcclusionPhantom> phantom;
  phantom->SetDimensions(40, 36, 44);
  for (int method : { vtkVolumetricAmbientOcclusion::CDF_RECONSTRUCTION,
         vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF, vtkVolumetricAmbientOcclusion::EXACT_SPHERE })
  {
    vtkNew<vtkVolumetricAmbientOcclusion> filter;
    filter->SetInputConnection(phantom->GetOutputPort());
    filter->SetMethod(method);
    filter->SetRadius(4);
    filter->ComputeVarianceOn();
    filter->Update();
    vtkNew<vtkImageData> whole;
    whole->DeepCopy(filter->GetOutput());
    const auto wholeAO = Values(whole->GetPointData()->GetArray("AmbientOcclusion"));
    const auto wholeVar = Values(whole->GetPointData()->GetArray("Variance"));
    for (int pieces : { 2, 3, 5 })
    {
      vtkIdType covered = 0;
      for (int piece = 0; piece < pieces; ++piece)
      {
        filter->UpdatePiece(piece, pieces, 0);
        vtkImageData* out = filter->GetOutput();
        const int* e = out->GetExtent();
        const int* in = phantom->GetOutput()->GetExtent();
        EXPECT_LT(phantom->GetOutput()->GetNumberOfPoints(), whole->GetNumberOfPoints())
          << "the source delivered the whole volume to a piece";
        for (int a = 0; a < 3; ++a)
        {
          EXPECT_GE(e[2 * a] - in[2 * a], 0);
          EXPECT_LE(e[2 * a] - in[2 * a], 4) << "input grown by more than the radius";
        }
        const auto ao = Values(out->GetPointData()->GetArray("AmbientOcclusion"));
        const auto var = Values(out->GetPointData()->GetArray("Variance"));
        ASSERT_EQ(static_cast<vtkIdType>(ao.size()), out->GetNumberOfPoints());
        ASSERT_EQ(
          out->GetPointData()->GetArray("Density")->GetNumberOfTuples(), out->GetNumberOfPoints());
        vtkIdType id = 0;
        for (int k = e[4]; k <= e[5]; ++k)
          for (int j = e[2]; j <= e[3]; ++j)
            for (int i = e[0]; i <= e[1]; ++i, ++id)
            {
              const vtkIdType w = (vtkIdType(k) * 36 + j) * 40 + i;
              ASSERT_EQ(ao[id], wholeAO[w])
                << "piece " << piece << "/" << pieces << " method " << method << " voxel " << i
                << "," << j << "," << k << " out extent z " << e[4] << ".." << e[5] << " input z "
                << in[4] << ".." << in[5];
              ASSERT_EQ(var[id], wholeVar[w]);
            }
        covered += out->GetNumberOfPoints();
      }
      // VTK's pieces split cells, so neighbouring pieces share their boundary points.
      EXPECT_GE(covered, whole->GetNumberOfPoints());
    }
  }
}

TEST(VolumetricAmbientOcclusion, RequestedSubExtentsEqualTheWholeResult)
{
  // Streaming by extent (UpdateExtent, as vtkImageDataStreamer and ParaView's slice views
  // ask), not by piece: the input is the extent grown by the radius, the output exactly
  // the extent asked for, and its values those of the whole run.
  const int dims[3] = { 30, 28, 33 };
  vtkNew<vtkAmbientOcclusionPhantom> phantom;
  phantom->SetDimensions(dims[0], dims[1], dims[2]);
  vtkNew<vtkVolumetricAmbientOcclusion> filter;
  filter->SetInputConnection(phantom->GetOutputPort());
  filter->SetMethod(vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF);
  filter->SetRadius(3);
  filter->Update();
  const auto wholeAO = Values(filter->GetOutput()->GetPointData()->GetArray("AmbientOcclusion"));
  const int extents[][6] = { { 0, 29, 0, 27, 10, 12 }, { 5, 9, 0, 27, 0, 32 },
    { 0, 0, 27, 27, 32, 32 }, { 12, 20, 3, 9, 15, 30 } };
  for (const auto& wanted : extents)
  {
    // A fresh pipeline per request: a cached whole output would already cover it.
    vtkNew<vtkAmbientOcclusionPhantom> source;
    source->SetDimensions(dims[0], dims[1], dims[2]);
    vtkNew<vtkVolumetricAmbientOcclusion> streamed;
    streamed->SetInputConnection(source->GetOutputPort());
    streamed->SetMethod(vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF);
    streamed->SetRadius(3);
    streamed->UpdateExtent(wanted);
    vtkImageData* out = streamed->GetOutput();
    const int* e = out->GetExtent();
    const int* in = source->GetOutput()->GetExtent();
    for (int a = 0; a < 6; ++a)
      ASSERT_EQ(e[a], wanted[a]) << "the output is not the requested extent";
    for (int a = 0; a < 3; ++a)
    {
      EXPECT_EQ(in[2 * a], std::max(0, wanted[2 * a] - 3))
        << "input not grown by exactly the radius";
      EXPECT_EQ(in[2 * a + 1], std::min(dims[a] - 1, wanted[2 * a + 1] + 3));
    }
    const auto ao = Values(out->GetPointData()->GetArray("AmbientOcclusion"));
    vtkIdType id = 0;
    for (int k = e[4]; k <= e[5]; ++k)
      for (int j = e[2]; j <= e[3]; ++j)
        for (int i = e[0]; i <= e[1]; ++i, ++id)
          ASSERT_EQ(ao[id], wholeAO[(vtkIdType(k) * 28 + j) * 30 + i]) << i << "," << j << "," << k;
  }
}

TEST(VolumetricAmbientOcclusion, BackendCudaFallsBackToCpuWithAWarning)
{
  auto image = RandomImage(8, 8, 8, 4);
  const FilterRun run = RunFilter(image,
    [](vtkVolumetricAmbientOcclusion* f)
    {
      f->SetRadius(2);
      f->SetBackend(vtkVolumetricAmbientOcclusion::BACKEND_CUDA);
    });
  EXPECT_TRUE(run.errors.empty());
  ASSERT_EQ(run.warnings.size(), 1u);
  EXPECT_NE(run.warnings[0].find("CPU"), std::string::npos);
  EXPECT_EQ(run.output->GetNumberOfPoints(), image->GetNumberOfPoints());
}

TEST(VolumetricAmbientOcclusion, ADeviceFailureFallsBackToTheCpuWithAWarning)
{
  const vao::cuda::DeviceStatus device = vao::cuda::deviceStatus();
  if (!device.available)
    GTEST_SKIP() << "no CUDA device: " << device.description
                 << " (the fallback without one is tested above)";
  auto image = RandomImage(40, 36, 30, 6);
  auto configure = [](vtkVolumetricAmbientOcclusion* f)
  {
    f->SetRadius(3);
    f->SetMethod(vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF);
  };
  const FilterRun cpu = RunFilter(image,
    [&](vtkVolumetricAmbientOcclusion* f)
    {
      configure(f);
      f->SetBackend(vtkVolumetricAmbientOcclusion::BACKEND_CPU);
    });
  vao::cuda::injectDeviceFailures(1); // as an error of the device after the upload would
  const FilterRun fallback = RunFilter(image,
    [&](vtkVolumetricAmbientOcclusion* f)
    {
      configure(f);
      f->SetBackend(vtkVolumetricAmbientOcclusion::BACKEND_CUDA);
    });
  vao::cuda::injectDeviceFailures(0);
  EXPECT_TRUE(fallback.errors.empty());
  ASSERT_EQ(fallback.warnings.size(), 1u);
  EXPECT_NE(fallback.warnings[0].find("injected"), std::string::npos) << fallback.warnings[0];
  EXPECT_NE(fallback.warnings[0].find("computing on the CPU"), std::string::npos)
    << fallback.warnings[0];
  auto* backend = vtkStringArray::SafeDownCast(
    fallback.output->GetFieldData()->GetAbstractArray("AmbientOcclusionBackend"));
  ASSERT_NE(backend, nullptr);
  EXPECT_EQ(backend->GetValue(0), "CPU");
  const auto expected = Values(cpu.output->GetPointData()->GetArray("AmbientOcclusion"));
  const auto got = Values(fallback.output->GetPointData()->GetArray("AmbientOcclusion"));
  ASSERT_EQ(got.size(), expected.size());
  for (size_t i = 0; i < got.size(); ++i)
    ASSERT_EQ(got[i], expected[i]) << "voxel " << i;
}

/// Every bad input: an error that says what is wrong, an empty output, no crash.
TEST(VolumetricAmbientOcclusion, RejectsBadInputWithAClearError)
{
  const auto radius = [](double r)
  { return [r](vtkVolumetricAmbientOcclusion* f) { f->SetRadius(r); }; };
  const auto none = [](vtkVolumetricAmbientOcclusion*) {};

  vtkNew<vtkImageData> noArray;
  noArray->SetDimensions(5, 5, 5);
  ExpectRejected(noArray, none, "No numeric point array");

  auto strings = RandomImage(5, 5, 5, 1);
  vtkNew<vtkStringArray> names;
  names->SetName("Names");
  names->SetNumberOfValues(125);
  strings->GetPointData()->RemoveArray("Density");
  strings->GetPointData()->AddArray(names);
  ExpectRejected(
    strings,
    [](vtkVolumetricAmbientOcclusion* f)
    { f->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "Names"); },
    "No numeric point array");

  auto cells = RandomImage(5, 5, 5, 1);
  vtkNew<vtkDoubleArray> cellValues;
  cellValues->SetName("CellValues");
  cellValues->SetNumberOfValues(cells->GetNumberOfCells());
  cells->GetCellData()->AddArray(cellValues);
  ExpectRejected(
    cells,
    [](vtkVolumetricAmbientOcclusion* f)
    { f->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_CELLS, "CellValues"); },
    "not a point-data array");

  // Scalars with fewer or more values than the image has points (read past their end
  // before), one and three components.
  for (vtkIdType tuples : { 5, 215, 217 })
    for (int components : { 1, 3 })
      ExpectRejected(
        WithPointArrayResized(RandomImage(6, 6, 6, 1, components), "Density", tuples),
        [](vtkVolumetricAmbientOcclusion* f) { f->SetComponent(0); },
        "Array 'Density' has " + std::to_string(tuples) + " tuples for the input's 216 points");

  ExpectRejected(RandomImage(6, 6, 6, 1, 3), radius(2), "set Component");
  ExpectRejected(
    RandomImage(6, 6, 6, 1, 3), [](vtkVolumetricAmbientOcclusion* f) { f->SetComponent(3); },
    "set Component");

  for (double bad : { std::nan(""), double(INFINITY), -double(INFINITY) })
  {
    auto image = RandomImage(6, 6, 6, 1);
    vtkNew<vtkFloatArray> values;
    values->DeepCopy(image->GetPointData()->GetScalars());
    values->SetName("Density");
    values->SetValue(100, static_cast<float>(bad));
    image->GetPointData()->SetScalars(values);
    ExpectRejected(image, radius(2), "NaN or infinite values (the first at voxel 7, 2, 7)");
  }

  vtkNew<vtkImageData> empty;
  ExpectRejected(empty, none, "needs a 3-D volume");
  auto single = RandomImage(1, 1, 1, 1);
  ExpectRejected(single, none, "needs a 3-D volume");
  auto flat = RandomImage(20, 20, 1, 1);
  ExpectRejected(flat, none, "needs a 3-D volume");

  ExpectRejected(RandomImage(6, 6, 6, 1), radius(0), "rounds to 0 voxels");
  for (double zero : { 0.0, -1.0, std::nan("") })
  {
    auto badSpacing = RandomImage(6, 6, 6, 1);
    badSpacing->SetSpacing(1, zero, 1);
    ExpectRejected(
      badSpacing,
      [](vtkVolumetricAmbientOcclusion* f)
      {
        f->SetRadiusUnits(vtkVolumetricAmbientOcclusion::WORLD);
        f->SetRadius(2);
      },
      "finite, positive spacing");
  }
  ExpectRejected(RandomImage(6, 6, 6, 1), radius(0.4), "rounds to 0 voxels");
  ExpectRejected(RandomImage(6, 6, 6, 1), radius(-3), "non-negative");
  ExpectRejected(RandomImage(6, 6, 6, 1), radius(std::nan("")), "finite");
  ExpectRejected(RandomImage(6, 7, 8, 1), radius(7), "covers the whole");
  ExpectRejected(RandomImage(6, 7, 8, 1), radius(1e300), "covers the whole");
  ExpectRejected(
    RandomImage(6, 6, 6, 1),
    [](vtkVolumetricAmbientOcclusion* f)
    {
      f->SetQueryMode(vtkVolumetricAmbientOcclusion::ISO_VALUE);
      f->SetIsoValue(std::nan(""));
    },
    "IsoValue");
  ExpectRejected(
    RandomImage(6, 6, 6, 1), [](vtkVolumetricAmbientOcclusion* f) { f->SetMethod(9); },
    "Unknown Method");
  ExpectRejected(
    RandomImage(6, 6, 6, 1), [](vtkVolumetricAmbientOcclusion* f) { f->SetNumberOfThreads(-1); },
    "NumberOfThreads");
  ExpectRejected(
    RandomImage(6, 6, 6, 1), [](vtkVolumetricAmbientOcclusion* f) { f->SetDevice(-2); },
    "Device must be -1");
  ExpectRejected(
    RandomImage(6, 6, 6, 1), [](vtkVolumetricAmbientOcclusion* f) { f->SetOutputArrayName(""); },
    "OutputArrayName");
  // The openness and the variance under one name: one would replace the other.
  ExpectRejected(
    RandomImage(6, 6, 6, 1),
    [](vtkVolumetricAmbientOcclusion* f)
    {
      f->SetOutputArrayName("Variance");
      f->ComputeVarianceOn();
    },
    "OutputArrayName 'Variance' is the name of the variance output");
}

TEST(VolumetricAmbientOcclusion, ARadiusLargerThanTheVolumeOnSomeAxesIsClipped)
{
  // A thin slab: the radius exceeds the z size but not x and y; the box is clipped.
  auto image = RandomImage(12, 12, 3, 5);
  const FilterRun run = RunFilter(image,
    [](vtkVolumetricAmbientOcclusion* f)
    {
      f->SetRadius(5);
      f->SetMethod(vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF);
    });
  ASSERT_TRUE(run.errors.empty());
  const int r[3] = { 5, 5, 5 };
  auto* ao = run.output->GetPointData()->GetArray("AmbientOcclusion");
  EXPECT_NEAR(ao->GetComponent(0, 0), ReferenceOpenness(image, 1, r, 3, -2, 5), 2e-6);
}

TEST(VolumetricAmbientOcclusion, AbortLeavesAnEmptyOutput)
{
  vtkNew<vtkAmbientOcclusionPhantom> phantom;
  phantom->SetDimensions(48, 48, 48);
  vtkNew<vtkVolumetricAmbientOcclusion> filter;
  filter->SetInputConnection(phantom->GetOutputPort());
  filter->SetMethod(vtkVolumetricAmbientOcclusion::EXACT_BOX);
  filter->SetRadius(6);
  int progressEvents = 0;
  vtkNew<vtkCallbackCommand> abortOnProgress;
  struct State
  {
    vtkVolumetricAmbientOcclusion* filter;
    int* events;
  } state{ filter, &progressEvents };
  abortOnProgress->SetClientData(&state);
  abortOnProgress->SetCallback(
    [](vtkObject*, unsigned long, void* client, void* call)
    {
      auto* s = static_cast<State*>(client);
      ++*s->events;
      if (*static_cast<double*>(call) > 0.2)
        s->filter->SetAbortExecute(1);
    });
  filter->AddObserver(vtkCommand::ProgressEvent, abortOnProgress);
  filter->Update();
  EXPECT_GT(progressEvents, 2);
  EXPECT_EQ(filter->GetOutput()->GetNumberOfPoints(), 0);
}

} // namespace
