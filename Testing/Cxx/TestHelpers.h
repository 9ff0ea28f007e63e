// Helpers shared by the VTK tests of the filters.
#pragma once

#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkDataSet.h"
#include "vtkImageData.h"
#include "vtkObject.h"
#include "vtkSmartPointer.h"

#include <array>
#include <functional>
#include <string>
#include <vector>

namespace vaotest
{

/// Collects the error and warning messages an object emits.
class MessageCatcher : public vtkCommand
{
public:
  static MessageCatcher* New() { return new MessageCatcher; }
  void Execute(vtkObject*, unsigned long event, void* data) override
  {
    const std::string text = data ? static_cast<const char*>(data) : "";
    (event == vtkCommand::ErrorEvent ? this->Errors : this->Warnings).push_back(text);
  }
  void Watch(vtkObject* object)
  {
    object->AddObserver(vtkCommand::ErrorEvent, this);
    object->AddObserver(vtkCommand::WarningEvent, this);
  }
  std::string AllErrors() const
  {
    std::string all;
    for (const auto& e : this->Errors)
      all += e;
    return all;
  }
  std::vector<std::string> Errors;
  std::vector<std::string> Warnings;
};

/// Path of a real scan: under Data/ (shipped with the repository) or, for the larger ones,
/// under VAO_EXTRA_DATA_DIR (a folder laid out the same way). The Data/ path when neither
/// has it, so that the reader's error names the file.
std::string DataFile(const std::string& relative);

/// Whether DataFile(relative) exists; tests of a scan that is not shipped skip without it:
/// `if (!HaveDataFile(f)) GTEST_SKIP() << MissingDataMessage(f);`
bool HaveDataFile(const std::string& relative);
std::string MissingDataMessage(const std::string& relative);

/// Reads a MetaImage volume; fails the calling test when it cannot.
vtkSmartPointer<vtkImageData> ReadMetaImage(const std::string& path);

/// Values of a one-component array as doubles.
std::vector<double> Values(vtkDataArray* array);

/// Component 0 of `field` (a point array of `image`; its scalars when null) at world point
/// x, trilinear between the voxels around it (reference::trilinear of ReferenceFormulas.h),
/// x clamped to the image; no direction matrix.
double Trilinear(vtkImageData* image, const double x[3], vtkDataArray* field = nullptr);

/// How `estimate` differs from `exact` over the voxels `counted` picks (every voxel without
/// it): the root mean square and the mean of estimate - exact (0 over no voxel).
struct Differences
{
  double rms = 0.0, mean = 0.0;
};
Differences Compare(const std::vector<double>& estimate, const std::vector<double>& exact,
  const std::function<bool(std::size_t)>& counted = {});

/// What every filter does with input it refuses: at least one error, one of which names
/// the problem (contains `words`, as written), and an output without points. For the
/// tests' wrappers that run each filter on the bad input (ExpectRejected).
void ExpectRefused(
  const std::vector<std::string>& errors, vtkDataSet* output, const std::string& words);

/// Fills `values` (any numeric array) with f(i, j, k) over the image's dimensions, x
/// fastest, names it "Density" and makes it the image's point scalars.
void SetDensity(
  vtkImageData* image, vtkDataArray* values, const std::function<double(int, int, int)>& f);

/// A ball in an image of `dims` points (origin 0, spacing 1): the points closer than
/// `radius` to `centre` (both in index units) are inside it. Its "Density" scalars, of
/// `values`' type, are value(inside, i, j, k) at point (i, j, k).
vtkSmartPointer<vtkImageData> Ball(vtkDataArray* values, const std::array<int, 3>& dims,
  const std::array<double, 3>& centre, double radius,
  const std::function<double(bool, int, int, int)>& value);

/// A copy of `data` whose point array `name` holds `tuples` tuples (its first ones, then
/// zeros): a point array that does not fit the points, which VTK lets a script attach.
vtkSmartPointer<vtkDataSet> WithPointArrayResized(
  vtkDataSet* data, const char* name, vtkIdType tuples);

} // namespace vaotest
