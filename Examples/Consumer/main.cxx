// Runs vtkVolumetricAmbientOcclusion from an installed VolumetricAO on the Wavelet
// (vtkRTAnalyticSource) and checks the output: a float32 point-data array
// "AmbientOcclusion", one value per point, every value finite and in [0, 1].
// Returns 0 on success, 1 otherwise.
#include <vtkDataArray.h>
#include <vtkDataObject.h>
#include <vtkFloatArray.h>
#include <vtkImageData.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkRTAnalyticSource.h>
#include <vtkVolumetricAmbientOcclusion.h>

#include <cmath>
#include <iostream>

int main()
{
  vtkNew<vtkRTAnalyticSource> source;
  source->SetWholeExtent(-10, 10, -10, 10, -10, 10);

  vtkNew<vtkVolumetricAmbientOcclusion> occlusion;
  occlusion->SetInputConnection(source->GetOutputPort());
  occlusion->SetInputArrayToProcess(0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, "RTData");
  occlusion->SetRadius(3);
  occlusion->Update();

  vtkImageData* output = occlusion->GetOutput();
  vtkDataArray* array = output ? output->GetPointData()->GetArray("AmbientOcclusion") : nullptr;
  if (!array)
  {
    std::cerr << "FAIL: no point-data array \"AmbientOcclusion\" in the output\n";
    return 1;
  }
  if (!vtkFloatArray::SafeDownCast(array))
  {
    std::cerr << "FAIL: \"AmbientOcclusion\" is a " << array->GetClassName()
              << ", not a vtkFloatArray\n";
    return 1;
  }
  if (array->GetNumberOfComponents() != 1 ||
    array->GetNumberOfTuples() != output->GetNumberOfPoints() ||
    output->GetNumberOfPoints() != 21 * 21 * 21)
  {
    std::cerr << "FAIL: \"AmbientOcclusion\" has " << array->GetNumberOfTuples() << " x "
              << array->GetNumberOfComponents() << " values for " << output->GetNumberOfPoints()
              << " points (expected 9261 x 1)\n";
    return 1;
  }

  double minimum = 1.0;
  double maximum = 0.0;
  vtkIdType bad = 0;
  for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i)
  {
    const double value = array->GetComponent(i, 0);
    if (!std::isfinite(value) || value < 0.0 || value > 1.0)
    {
      ++bad;
      continue;
    }
    minimum = value < minimum ? value : minimum;
    maximum = value > maximum ? value : maximum;
  }

  const char* backend = occlusion->GetLastBackend();
  std::cout << "AmbientOcclusion range: [" << minimum << ", " << maximum << "] over "
            << array->GetNumberOfTuples() << " points, backend "
            << (backend && *backend ? backend : "(not reported)") << "\n";
  if (bad > 0)
  {
    std::cerr << "FAIL: " << bad << " values are NaN, infinite or outside [0, 1]\n";
    return 1;
  }
  if (!(maximum > minimum))
  {
    std::cerr << "FAIL: the openness is constant on the Wavelet\n";
    return 1;
  }
  std::cout << "OK\n";
  return 0;
}
