// vao-demo's volume file: the input's array and every result in one .vti, written with
// inline binary data and read back with VTK's reader to check every array.
#include "DemoVolumeFile.h"

#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkXMLImageDataReader.h"
#include "vtkXMLImageDataWriter.h"

#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

namespace vaodemo
{
namespace
{

std::string DifferingArrays(vtkImageData* expected, vtkImageData* actual)
{
  std::string differing;
  for (int a = 0; a < expected->GetPointData()->GetNumberOfArrays(); ++a)
  {
    vtkDataArray* want = expected->GetPointData()->GetArray(a);
    vtkDataArray* got = actual->GetPointData()->GetArray(want->GetName());
    const int components = want->GetNumberOfComponents();
    bool same = got && got->GetDataType() == want->GetDataType() &&
      got->GetNumberOfTuples() == want->GetNumberOfTuples() &&
      got->GetNumberOfComponents() == components;
    for (vtkIdType t = 0; same && t < want->GetNumberOfTuples(); ++t)
    {
      for (int c = 0; same && c < components; ++c)
      {
        same = got->GetComponent(t, c) == want->GetComponent(t, c);
      }
    }
    if (!same)
    {
      differing += std::string(differing.empty() ? "" : ", ") + want->GetName();
    }
  }
  return differing;
}

} // namespace

vtkSmartPointer<vtkImageData> AssembleResult(
  vtkImageData* input, vtkDataArray* scalars, const std::vector<Computation>& results)
{
  auto result = vtkSmartPointer<vtkImageData>::New();
  result->CopyStructure(input);
  result->GetPointData()->SetScalars(scalars);
  for (const Computation& c : results)
  {
    result->GetPointData()->AddArray(c.values);
  }
  return result;
}

void WriteVolume(vtkImageData* image, const std::string& path)
{
  vtkNew<vtkXMLImageDataWriter> writer;
  writer->SetInputData(image);
  writer->SetFileName(path.c_str());
  // Inline binary: this VTK 9.2 (with the system's expat) cannot read appended data back.
  writer->SetDataModeToBinary();
  ErrorLog errors(writer);
  if (!writer->Write())
  {
    Fail(ExitFailure, "cannot write '" + path + "': " + errors.Text("the writer failed."));
  }
}

/// Names of the arrays that differ between `expected` and `actual` (empty: identical).
void CheckVolumeReadBack(vtkImageData* written, const std::string& path)
{
  const auto start = std::chrono::steady_clock::now();
  vtkNew<vtkXMLImageDataReader> reader;
  reader->SetFileName(path.c_str());
  ErrorLog errors(reader);
  reader->Update();
  vtkImageData* read = reader->GetOutput();
  int writtenDims[3], readDims[3];
  written->GetDimensions(writtenDims);
  read->GetDimensions(readDims);
  if (read->GetNumberOfPoints() == 0 || !std::equal(writtenDims, writtenDims + 3, readDims))
  {
    Fail(ExitFailure, "read back of '" + path + "' failed: " + errors.Text("wrong dimensions."));
  }
  const std::string differing = DifferingArrays(written, read);
  if (!differing.empty())
  {
    Fail(
      ExitFailure, "read back of '" + path + "' failed: these arrays differ: " + differing + ".");
  }
  std::printf("read back: OK (%d arrays of %lld voxels, identical, checked in %.2f s)\n",
    written->GetPointData()->GetNumberOfArrays(),
    static_cast<long long>(written->GetNumberOfPoints()), SecondsSince(start));
}

} // namespace vaodemo
