// The filter with Histogram CDF and the smoothed query: streaming gives the whole run's
// numbers, bad settings give a clear error, the smoothed query is in voxels whatever the
// spacing, and the thresholds kept on an array hold only while it is unchanged.
#include "ReferenceFormulas.h"
#include "VolumetricTestSupport.h"

#include "vtkAmbientOcclusionPhantom.h"
#include "vtkAmbientOcclusionThresholds.h"

#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"

#include <cmath>

using namespace vaotest;

namespace
{

vtkSmartPointer<vtkImageData> WholeRun(
  int dims[3], const std::function<void(vtkVolumetricAmbientOcclusion*)>& configure)
{
  vtkNew<vtkAmbientOcclusionPhantom> phantom;
  phantom->SetDimensions(dims[0], dims[1], dims[2]);
  vtkNew<vtkVolumetricAmbientOcclusion> filter;
  filter->SetInputConnection(phantom->GetOutputPort());
  configure(filter);
  filter->Update();
  auto copy = vtkSmartPointer<vtkImageData>::New();
  copy->DeepCopy(filter->GetOutput());
  return copy;
}

/// Every piece or sub-extent of a fresh pipeline equals the whole run, voxel for voxel.
void ExpectStreamingEqualsWhole(
  const std::function<void(vtkVolumetricAmbientOcclusion*)>& configure)
{
  int dims[3] = { 34, 30, 37 };
  auto whole = WholeRun(dims, configure);
  const auto wholeAO = Values(whole->GetPointData()->GetArray("AmbientOcclusion"));
  ASSERT_EQ(static_cast<int>(wholeAO.size()), dims[0] * dims[1] * dims[2]);
  auto expectMatches = [&](vtkImageData* out, const std::string& what)
  {
    const int* e = out->GetExtent();
    const auto ao = Values(out->GetPointData()->GetArray("AmbientOcclusion"));
    ASSERT_EQ(static_cast<vtkIdType>(ao.size()), out->GetNumberOfPoints()) << what;
    vtkIdType id = 0;
    for (int k = e[4]; k <= e[5]; ++k)
      for (int j = e[2]; j <= e[3]; ++j)
        for (int i = e[0]; i <= e[1]; ++i, ++id)
          ASSERT_EQ(ao[id], wholeAO[(vtkIdType(k) * dims[1] + j) * dims[0] + i])
            << what << " " << i << "," << j << "," << k;
  };
  for (int pieces : { 2, 3, 5 })
  {
    vtkNew<vtkAmbientOcclusionPhantom> phantom;
    phantom->SetDimensions(dims[0], dims[1], dims[2]);
    vtkNew<vtkVolumetricAmbientOcclusion> filter;
    filter->SetInputConnection(phantom->GetOutputPort());
    configure(filter);
    for (int piece = 0; piece < pieces; ++piece)
    {
      filter->UpdatePiece(piece, pieces, 0);
      expectMatches(
        filter->GetOutput(), "piece " + std::to_string(piece) + "/" + std::to_string(pieces));
    }
  }
  const int extents[][6] = { { 0, 33, 0, 29, 10, 12 }, { 5, 9, 0, 29, 0, 36 },
    { 12, 20, 3, 9, 15, 30 } };
  for (const auto& wanted : extents)
  {
    vtkNew<vtkAmbientOcclusionPhantom> source;
    source->SetDimensions(dims[0], dims[1], dims[2]);
    vtkNew<vtkVolumetricAmbientOcclusion> streamed;
    streamed->SetInputConnection(source->GetOutputPort());
    configure(streamed);
    streamed->UpdateExtent(wanted);
    for (int a = 0; a < 6; ++a)
      ASSERT_EQ(streamed->GetOutput()->GetExtent()[a], wanted[a])
        << "the output is not the requested extent";
    expectMatches(streamed->GetOutput(), "extent");
  }
}

} // namespace

TEST(HistogramCdfFilter, IsTheDefaultMethod)
{
  vtkNew<vtkVolumetricAmbientOcclusion> filter;
  EXPECT_EQ(filter->GetMethod(), vtkVolumetricAmbientOcclusion::HISTOGRAM_CDF);
  EXPECT_EQ(filter->GetNumberOfBins(), 64);
  EXPECT_EQ(filter->GetQuerySmoothing(), 1.0);
}

TEST(HistogramCdfFilter, StreamedPiecesAndExtentsEqualTheWholeRun)
{
  ExpectStreamingEqualsWhole([](vtkVolumetricAmbientOcclusion* f) { f->SetRadius(4); });
  ExpectStreamingEqualsWhole(
    [](vtkVolumetricAmbientOcclusion* f)
    {
      f->SetRadius(3);
      f->SetNumberOfBins(7);
      f->SetQueryMode(vtkVolumetricAmbientOcclusion::SMOOTHED_VALUE);
      f->SetQuerySmoothing(1.8);
    });
}

TEST(HistogramCdfFilter, TheSmoothedQueryStreamsWithEveryMethod)
{
  // A window (ceil(3 x 2) = 6 voxels) wider than the radius: the input must grow by it.
  for (int method :
    { vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF, vtkVolumetricAmbientOcclusion::EXACT_BOX })
    ExpectStreamingEqualsWhole(
      [method](vtkVolumetricAmbientOcclusion* f)
      {
        f->SetMethod(method);
        f->SetRadius(2);
        f->SetQueryMode(vtkVolumetricAmbientOcclusion::SMOOTHED_VALUE);
        f->SetQuerySmoothing(2.0);
      });
}

TEST(HistogramCdfFilter, TheSmoothedQueryIsInVoxelsWhateverTheSpacing)
{
  // Exact Box with the smoothed query against the definition, on an image with spacing
  // 2 x 1 x 0.5 and an offset extent (RandomImage); the result must not depend on it.
  for (double sigma : { 0.7, 1.0, 2.5 })
  {
    auto image = RandomImage(11, 9, 8, 7);
    const FilterRun run = RunFilter(image,
      [sigma](vtkVolumetricAmbientOcclusion* f)
      {
        f->SetMethod(vtkVolumetricAmbientOcclusion::EXACT_BOX);
        f->SetRadius(2);
        f->SetQueryMode(vtkVolumetricAmbientOcclusion::SMOOTHED_VALUE);
        f->SetQuerySmoothing(sigma);
      });
    ASSERT_TRUE(run.errors.empty());
    const auto ao = Values(run.output->GetPointData()->GetArray("AmbientOcclusion"));
    const auto v = Values(image->GetPointData()->GetScalars());
    const int n[3] = { 11, 9, 8 };
    const int w = static_cast<int>(std::ceil(3 * sigma));
    auto at = [&](int x, int y, int z) { return v[(z * n[1] + y) * n[0] + x]; };
    int id = 0;
    for (int z = 0; z < n[2]; ++z)
      for (int y = 0; y < n[1]; ++y)
        for (int x = 0; x < n[0]; ++x, ++id)
        {
          long double num = 0, den = 0;
          for (int k = std::max(0, z - w); k <= std::min(n[2] - 1, z + w); ++k)
            for (int j = std::max(0, y - w); j <= std::min(n[1] - 1, y + w); ++j)
              for (int i = std::max(0, x - w); i <= std::min(n[0] - 1, x + w); ++i)
              {
                const long double g =
                  std::exp(-((i - x) * (i - x) + (j - y) * (j - y) + (k - z) * (k - z)) /
                    (2.0L * sigma * sigma));
                num += g * at(i, j, k);
                den += g;
              }
          double q = static_cast<double>(num / den);
          if (std::abs(q - std::nearbyint(q)) <= 1e-9 * std::max(1.0, std::abs(q)))
            q = std::nearbyint(q); // integer data: the library snaps rounding onto the value
          double below = 0, total = 0;
          for (int k = std::max(0, z - 2); k <= std::min(n[2] - 1, z + 2); ++k)
            for (int j = std::max(0, y - 2); j <= std::min(n[1] - 1, y + 2); ++j)
              for (int i = std::max(0, x - 2); i <= std::min(n[0] - 1, x + 2); ++i)
              {
                total += 1;
                below += at(i, j, k) <= q ? 1 : 0;
              }
          ASSERT_NEAR(ao[id], below / total, 1e-6)
            << "sigma " << sigma << " voxel " << x << "," << y << "," << z;
        }
  }
}

TEST(HistogramCdfFilter, RejectsBadBinsAndSmoothing)
{
  for (int bins : { -3, 0, 1, 1025, 100000 })
    ExpectRejected(
      RandomImage(6, 6, 6, 1),
      [bins](vtkVolumetricAmbientOcclusion* f) { f->SetNumberOfBins(bins); },
      "NumberOfBins must lie in [2, 1024]");
  for (double sigma : { 0.0, -1.0, std::nan(""), double(INFINITY), 150.0 })
    ExpectRejected(
      RandomImage(6, 6, 6, 1),
      [sigma](vtkVolumetricAmbientOcclusion* f)
      {
        f->SetQueryMode(vtkVolumetricAmbientOcclusion::SMOOTHED_VALUE);
        f->SetQuerySmoothing(sigma);
      },
      "QuerySmoothing");
  ExpectRejected(
    RandomImage(6, 6, 6, 1), [](vtkVolumetricAmbientOcclusion* f) { f->SetQueryMode(3); },
    "Unknown QueryMode");
  // Bins that another method ignores are no error for it.
  const FilterRun run = RunFilter(RandomImage(6, 6, 6, 1),
    [](vtkVolumetricAmbientOcclusion* f)
    {
      f->SetMethod(vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF);
      f->SetRadius(1);
      f->SetNumberOfBins(0);
    });
  EXPECT_TRUE(run.errors.empty());
  EXPECT_EQ(run.output->GetNumberOfPoints(), 216);
}

TEST(HistogramCdfFilter, NonFiniteValuesAreNamed)
{
  auto image = RandomImage(6, 6, 6, 1);
  vtkNew<vtkFloatArray> values;
  values->DeepCopy(image->GetPointData()->GetScalars());
  values->SetName("Density");
  values->SetValue(100, std::nanf(""));
  image->GetPointData()->SetScalars(values);
  ExpectRejected(
    image, [](vtkVolumetricAmbientOcclusion* f) { f->SetRadius(2); },
    "NaN or infinite values (the first at voxel 7, 2, 7)");
}

TEST(HistogramCdfFilter, GivenThresholdsStreamOnlyTheGrownPiece)
{
  int dims[3] = { 34, 30, 37 };
  auto whole = WholeRun(dims, [](vtkVolumetricAmbientOcclusion* f) { f->SetRadius(3); });
  vtkDataArray* used = whole->GetFieldData()->GetArray("HistogramThresholds");
  ASSERT_NE(used, nullptr) << "the output carries the thresholds it used";
  EXPECT_EQ(used->GetNumberOfTuples(), 64);

  // The same thresholds, read slab by slab from a fresh pipeline.
  vtkNew<vtkAmbientOcclusionPhantom> source;
  source->SetDimensions(dims[0], dims[1], dims[2]);
  vtkNew<vtkVolumetricAmbientOcclusion> streamed;
  streamed->SetInputConnection(source->GetOutputPort());
  streamed->SetRadius(3);
  vtkSmartPointer<vtkDoubleArray> computed = streamed->ComputeHistogramThresholds(5);
  ASSERT_NE(computed, nullptr);
  ASSERT_EQ(computed->GetNumberOfTuples(), used->GetNumberOfTuples());
  for (vtkIdType i = 0; i < computed->GetNumberOfTuples(); ++i)
    ASSERT_EQ(computed->GetValue(i), used->GetComponent(i, 0)) << i;
  EXPECT_LT(source->GetOutput()->GetNumberOfPoints(), dims[0] * dims[1] * dims[2])
    << "a slab, not the volume";

  // With them given, a sub-extent needs only itself grown by the radius.
  streamed->SetHistogramThresholds(computed);
  const int wanted[6] = { 4, 20, 0, 29, 10, 14 };
  streamed->UpdateExtent(wanted);
  const int* in = source->GetOutput()->GetExtent();
  EXPECT_EQ(in[4], 7);
  EXPECT_EQ(in[5], 17);
  const auto ao = Values(streamed->GetOutput()->GetPointData()->GetArray("AmbientOcclusion"));
  const auto wholeAO = Values(whole->GetPointData()->GetArray("AmbientOcclusion"));
  vtkIdType id = 0;
  for (int k = wanted[4]; k <= wanted[5]; ++k)
    for (int j = wanted[2]; j <= wanted[3]; ++j)
      for (int i = wanted[0]; i <= wanted[1]; ++i, ++id)
        ASSERT_EQ(ao[id], wholeAO[(vtkIdType(k) * dims[1] + j) * dims[0] + i])
          << i << "," << j << "," << k;
}

TEST(HistogramCdfFilter, RejectsBadGivenThresholds)
{
  for (const std::vector<double>& bad :
    { std::vector<double>{ 5.0, 1.0 }, std::vector<double>{}, { 0.0, std::nan("") } })
  {
    vtkNew<vtkDoubleArray> thresholds;
    for (const double t : bad)
      thresholds->InsertNextValue(t);
    ExpectRejected(
      RandomImage(6, 6, 6, 1),
      [&](vtkVolumetricAmbientOcclusion* f) { f->SetHistogramThresholds(thresholds); },
      "HistogramThresholds");
  }
}

TEST(HistogramCdfFilter, ThresholdsAreKeptOnTheArrayWhileItIsUnchanged)
{
  auto image = RandomImage(20, 17, 23, 11);
  auto fresh = vtkSmartPointer<vtkImageData>::New(); // the same values, nothing kept
  fresh->DeepCopy(image);
  vtkDataArray* values = image->GetPointData()->GetScalars();
  auto run = [&](vtkImageData* input, int bins)
  {
    vtkNew<vtkVolumetricAmbientOcclusion> filter;
    filter->SetInputData(input);
    filter->SetRadius(2);
    filter->SetNumberOfBins(bins);
    filter->Update();
    vtkDataArray* used = filter->GetOutput()->GetFieldData()->GetArray("HistogramThresholds");
    return used ? Values(used) : std::vector<double>{};
  };
  const std::vector<double> counted = run(image, 64);
  ASSERT_FALSE(counted.empty());
  // Another filter on the same, unchanged array takes the thresholds kept on it: planted
  // ones show that it read them instead of counting.
  std::vector<double> planted = counted;
  for (double& t : planted)
    t = 2.0 * t + 1.0;
  vtkAmbientOcclusionThresholds::Remember(values, -1, 64, planted);
  EXPECT_EQ(run(image, 64), planted);
  // Other bins are counted afresh, and so is the array once it is Modified().
  EXPECT_EQ(run(image, 16), run(fresh, 16));
  values->Modified();
  EXPECT_EQ(run(image, 64), counted);
  // Changed values (and Modified) give their own thresholds, those of a fresh copy.
  for (vtkIdType i = 0; i < values->GetNumberOfValues(); ++i)
    values->SetComponent(i, 0, 3.0 * values->GetComponent(i, 0));
  values->Modified();
  fresh->DeepCopy(image);
  const std::vector<double> changed = run(image, 64);
  EXPECT_EQ(changed, run(fresh, 64));
  EXPECT_NE(changed, counted);
}
