#include "TestHelpers.h"

#include "vtkMetaImageReader.h"
#include "vtkNew.h"

#include <gtest/gtest.h>

namespace vaotest
{

vtkSmartPointer<vtkImageData> ReadMetaImage(const std::string& path)
{
  vtkNew<vtkMetaImageReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkSmartPointer<vtkImageData> image = reader->GetOutput();
  EXPECT_GT(image->GetNumberOfPoints(), 0) << "cannot read " << path;
  return image;
}

std::vector<double> Values(vtkDataArray* array)
{
  std::vector<double> values(static_cast<size_t>(array->GetNumberOfTuples()));
  for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i)
    values[i] = array->GetComponent(i, 0);
  return values;
}

} // namespace vaotest
