// The filter on real scans: the reference errors of docs/methods.md (Ruiz et al.) and a
// regression image.
#include "TestHelpers.h"

#include "vtkAmbientOcclusionPhantom.h"
#include "vtkVolumetricAmbientOcclusion.h"

#include "vtkExtractVOI.h"
#include "vtkFloatArray.h"
#include "vtkImageDifference.h"
#include "vtkImageMapToColors.h"
#include "vtkLookupTable.h"
#include "vtkNew.h"
#include "vtkPNGReader.h"
#include "vtkPNGWriter.h"
#include "vtkPointData.h"

#include <gtest/gtest.h>

#include <cmath>
#include <fstream>

using namespace vaotest;

namespace
{

std::vector<double> AmbientOcclusion(vtkImageData* image, int method, double radius)
{
  vtkNew<vtkVolumetricAmbientOcclusion> filter;
  filter->SetInputData(image);
  filter->SetMethod(method);
  filter->SetRadius(radius);
  filter->Update();
  vtkDataArray* ao = filter->GetOutput()->GetPointData()->GetArray("AmbientOcclusion");
  EXPECT_NE(ao, nullptr);
  return ao ? Values(ao) : std::vector<double>();
}

/// docs/methods.md (Ruiz et al., reference errors): RMSE against Exact Box on the
/// 128x128x136 CT head phantom, to +-0.005.
void ExpectPublishedRmse(double radius, double gaussian, double cdf, double chebyshev)
{
  auto ct = ReadMetaImage(DataFile("ct_head_phantom/ct_head_phantom_128x128x136_int16.mha"));
  ASSERT_EQ(ct->GetNumberOfPoints(), 128 * 128 * 136);
  const auto exact = AmbientOcclusion(ct, vtkVolumetricAmbientOcclusion::EXACT_BOX, radius);
  const Differences g =
    Compare(AmbientOcclusion(ct, vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF, radius), exact);
  const Differences c =
    Compare(AmbientOcclusion(ct, vtkVolumetricAmbientOcclusion::CDF_RECONSTRUCTION, radius), exact);
  const Differences b =
    Compare(AmbientOcclusion(ct, vtkVolumetricAmbientOcclusion::CHEBYSHEV, radius), exact);
  std::cout << "R = " << radius << ": RMSE Gaussian CDF " << g.rms << ", CDF Reconstruction "
            << c.rms << ", Chebyshev " << b.rms << " (bias " << b.mean << ")" << std::endl;
  EXPECT_NEAR(g.rms, gaussian, 0.005);
  EXPECT_NEAR(c.rms, cdf, 0.005);
  EXPECT_NEAR(b.rms, chebyshev, 0.005);
  if (radius == 5)
    EXPECT_NEAR(b.mean, -0.40, 0.01);
}

TEST(RealScans, PublishedRmseOnTheCtHeadPhantomAtRadius5)
{
  ExpectPublishedRmse(5, 0.120, 0.182, 0.433);
}

TEST(RealScans, PublishedRmseOnTheCtHeadPhantomAtRadius10)
{
  ExpectPublishedRmse(10, 0.143, 0.212, 0.440);
}

/// Middle axial slice of the AO, grey-mapped to RGB.
vtkSmartPointer<vtkImageData> ColourMappedSlice(vtkImageData* volume, const char* array)
{
  const int* e = volume->GetExtent();
  vtkNew<vtkExtractVOI> slice;
  slice->SetInputData(volume);
  slice->SetVOI(e[0], e[1], e[2], e[3], (e[4] + e[5]) / 2, (e[4] + e[5]) / 2);
  vtkNew<vtkLookupTable> lut;
  lut->SetTableRange(0.0, 1.0);
  lut->SetHueRange(0.6, 0.0); // blue (occluded) to red (open): banding would show
  lut->SetNumberOfTableValues(256);
  lut->Build();
  vtkNew<vtkImageMapToColors> colours;
  colours->SetInputConnection(slice->GetOutputPort());
  colours->SetLookupTable(lut);
  colours->SetOutputFormatToRGB();
  colours->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, array);
  colours->Update();
  // At z = 0, as the PNG reader delivers the baseline.
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->DeepCopy(colours->GetOutput());
  image->SetExtent(e[0], e[1], e[2], e[3], 0, 0);
  return image;
}

double ImageError(vtkImageData* image, vtkImageData* baseline)
{
  for (int a = 0; a < 6; ++a)
  {
    if (image->GetExtent()[a] != baseline->GetExtent()[a])
    {
      ADD_FAILURE() << "the image and its baseline differ in size";
      return 1e30;
    }
  }
  vtkNew<vtkImageDifference> difference;
  difference->SetInputData(image);
  difference->SetImageData(baseline);
  difference->Update();
  return difference->GetThresholdedError();
}

TEST(RealScans, RegressionImageOfAnAmbientOcclusionSlice)
{
  vtkNew<vtkAmbientOcclusionPhantom> phantom;
  phantom->SetDimensions(128, 128, 128);
  vtkNew<vtkVolumetricAmbientOcclusion> filter;
  filter->SetInputConnection(phantom->GetOutputPort());
  filter->SetMethod(vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF);
  filter->SetRadius(5);
  filter->SetBackend(vtkVolumetricAmbientOcclusion::BACKEND_CPU);
  filter->Update();
  vtkNew<vtkImageData> volume;
  volume->DeepCopy(filter->GetOutput());
  auto image = ColourMappedSlice(volume, "AmbientOcclusion");

  const std::string baselinePath = std::string(VAO_BASELINE_DIR) + "/PhantomAOSlice.png";
  const std::string outputPath = std::string(VAO_TEST_OUTPUT_DIR) + "/PhantomAOSlice.png";
  vtkNew<vtkPNGWriter> writer;
  writer->SetInputData(image);
  writer->SetFileName(outputPath.c_str());
  writer->Write();
  if (std::getenv("VAO_WRITE_BASELINES"))
  {
    writer->SetFileName(baselinePath.c_str());
    writer->Write();
  }
  vtkNew<vtkPNGReader> reader;
  ASSERT_TRUE(std::ifstream(baselinePath).good()) << "missing baseline " << baselinePath;
  reader->SetFileName(baselinePath.c_str());
  reader->Update();
  const double error = ImageError(image, reader->GetOutput());
  std::cout << "regression image error " << error << " (written to " << outputPath << ")"
            << std::endl;
  EXPECT_LT(error, 10.0);

  // The comparison can fail: a constant AO field is far from the baseline.
  vtkNew<vtkFloatArray> constant;
  constant->SetName("Constant");
  constant->SetNumberOfTuples(volume->GetNumberOfPoints());
  constant->Fill(0.5f);
  volume->GetPointData()->AddArray(constant);
  const double constantError =
    ImageError(ColourMappedSlice(volume, "Constant"), reader->GetOutput());
  std::cout << "constant-AO image error " << constantError << std::endl;
  EXPECT_GT(constantError, 100.0);
}

} // namespace
