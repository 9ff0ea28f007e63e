#include "TestHelpers.h"
#include "ScanPath.h"

#include "ReferenceFormulas.h"

#include "vtkMetaImageReader.h"
#include "vtkNew.h"
#include "vtkPointData.h"

#include <algorithm>
#include <cmath>
#include <fstream>

#include <gtest/gtest.h>

namespace vaotest
{

std::string DataFile(const std::string& relative)
{
  return vaodata::ScanPath(VAO_DATA_DIR, VAO_EXTRA_DATA_DIR, relative);
}

bool HaveDataFile(const std::string& relative)
{
  return std::ifstream(DataFile(relative)).good();
}

std::string MissingDataMessage(const std::string& relative)
{
  return relative +
    " is not shipped in Data/: configure with -DVAO_EXTRA_DATA_DIR=DIR, DIR holding " + relative +
    " (VAO_EXTRA_DATA_DIR is now '" + VAO_EXTRA_DATA_DIR + "')";
}

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

void SetDensity(
  vtkImageData* image, vtkDataArray* values, const std::function<double(int, int, int)>& f)
{
  const int* d = image->GetDimensions();
  values->SetName("Density");
  values->SetNumberOfComponents(1);
  values->SetNumberOfTuples(image->GetNumberOfPoints());
  vtkIdType id = 0;
  for (int k = 0; k < d[2]; ++k)
    for (int j = 0; j < d[1]; ++j)
      for (int i = 0; i < d[0]; ++i, ++id)
        values->SetComponent(id, 0, f(i, j, k));
  image->GetPointData()->SetScalars(values);
}

vtkSmartPointer<vtkImageData> Ball(vtkDataArray* values, const std::array<int, 3>& dims,
  const std::array<double, 3>& centre, double radius,
  const std::function<double(bool, int, int, int)>& value)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(dims[0], dims[1], dims[2]);
  SetDensity(image, values,
    [&](int i, int j, int k)
    {
      const double dx = i - centre[0], dy = j - centre[1], dz = k - centre[2];
      return value(std::sqrt(dx * dx + dy * dy + dz * dz) < radius, i, j, k);
    });
  return image;
}

vtkSmartPointer<vtkDataSet> WithPointArrayResized(
  vtkDataSet* data, const char* name, vtkIdType tuples)
{
  vtkSmartPointer<vtkDataSet> copy = vtk::TakeSmartPointer(data->NewInstance());
  copy->DeepCopy(data);
  vtkDataArray* array = copy->GetPointData()->GetArray(name);
  EXPECT_NE(array, nullptr) << name;
  if (array)
  {
    const vtkIdType kept = std::min(tuples, array->GetNumberOfTuples());
    array->Resize(tuples); // keeps the first tuples; its pointer and length follow the new size
    array->SetNumberOfTuples(tuples);
    for (vtkIdType i = kept; i < tuples; ++i)
      for (int c = 0; c < array->GetNumberOfComponents(); ++c)
        array->SetComponent(i, c, 0.0);
  }
  return copy;
}

void ExpectRefused(
  const std::vector<std::string>& errors, vtkDataSet* output, const std::string& words)
{
  ASSERT_FALSE(errors.empty()) << "no error for: " << words;
  const bool named = std::any_of(errors.begin(), errors.end(),
    [&](const std::string& e) { return e.find(words) != std::string::npos; });
  EXPECT_TRUE(named) << "no error mentions '" << words << "': " << errors[0];
  ASSERT_NE(output, nullptr);
  EXPECT_EQ(output->GetNumberOfPoints(), 0);
}

Differences Compare(const std::vector<double>& estimate, const std::vector<double>& exact,
  const std::function<bool(std::size_t)>& counted)
{
  double squares = 0.0, sum = 0.0;
  std::size_t count = 0;
  for (std::size_t i = 0; i < exact.size(); ++i)
  {
    if (counted && !counted(i))
      continue;
    const double d = estimate[i] - exact[i];
    squares += d * d;
    sum += d;
    ++count;
  }
  if (count == 0)
    return {};
  return { std::sqrt(squares / count), sum / count };
}

double Trilinear(vtkImageData* image, const double x[3], vtkDataArray* field)
{
  vtkDataArray* values = field ? field : image->GetPointData()->GetScalars();
  const int* ext = image->GetExtent();
  const std::array<long long, 3> dims = { ext[1] - ext[0] + 1, ext[3] - ext[2] + 1,
    ext[5] - ext[4] + 1 };
  std::array<double, 3> first, spacing, point;
  for (int a = 0; a < 3; ++a)
  {
    spacing[a] = image->GetSpacing()[a];
    first[a] = image->GetOrigin()[a] + ext[2 * a] * spacing[a];
    point[a] = x[a];
  }
  return reference::trilinear(dims, first, spacing, point,
    [&](long long i, long long j, long long k)
    { return values->GetComponent((k * dims[1] + j) * dims[0] + i, 0); });
}

} // namespace vaotest
