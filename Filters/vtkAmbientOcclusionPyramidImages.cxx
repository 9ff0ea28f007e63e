#include "vtkAmbientOcclusionPyramidImages.h"

#include "vtkAmbientOcclusionExtents.h"
#include "vtkAmbientOcclusionRanges.h"

#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkObject.h"
#include "vtkPointData.h"

#include <algorithm>
#include <utility>

namespace vtkAmbientOcclusionPyramidImages
{

std::array<double, 3> ExtentOrigin(vtkImageData* image)
{
  const double* o = image->GetOrigin();
  const double* h = image->GetSpacing();
  const int* e = image->GetExtent();
  return { o[0] + e[0] * h[0], o[1] + e[2] * h[1], o[2] + e[4] * h[2] };
}

bool BuildPyramid(const vtkAmbientOcclusionArrayInput::ScalarVolume& scalars, vtkImageData* input,
  const vao::PyramidParameters& parameters, const vao::Execution& execution,
  std::vector<vao::MomentLevel>& pyramid, std::string& error)
{
  const double* h = input->GetSpacing();
  const vao::Status status = vao::buildMomentPyramid(
    scalars.view, ExtentOrigin(input), { h[0], h[1], h[2] }, parameters, pyramid, execution);
  error = vtkAmbientOcclusionArrayInput::KernelError(
    status, scalars, "The variance occlusion map failed");
  return status.ok;
}

bool BuildPyramid(const vtkAmbientOcclusionArrayInput::ScalarVolume& scalars, vtkImageData* input,
  const vao::PyramidParameters& parameters, const vao::Execution& execution,
  vao::SurfacePyramid& pyramid, std::string& error)
{
  const double* h = input->GetSpacing();
  const vao::Status status = vao::buildSurfacePyramid(
    scalars.view, ExtentOrigin(input), { h[0], h[1], h[2] }, parameters, pyramid, execution);
  error = vtkAmbientOcclusionArrayInput::KernelError(
    status, scalars, "The variance occlusion map failed");
  return status.ok;
}

void WarnOfCoarseMeans(vtkObject* owner, const std::vector<vao::MomentLevel>& levels)
{
  const double resolution = levels.empty() ? 0.0 : vao::meanResolution(levels.back());
  if (resolution > vao::kCoarseMeanResolution)
  {
    vtkWarningWithObjectMacro(
      owner, << "The values lie far from 0 against their spread: the pyramid's float32 "
                "means resolve "
             << resolution << " of it (above " << vao::kCoarseMeanResolution
             << "), so AO and shadows lose precision. Subtract an offset first (e.g. "
                "with the Calculator).");
  }
}

vao::MomentLevel WholeLevelGeometry(vtkImageData* volume, const int whole[6], int step)
{
  vao::MomentLevel level;
  const double* h = volume->GetSpacing();
  const double* origin = volume->GetOrigin();
  for (int a = 0; a < 3; ++a)
  {
    // Each halving keeps voxels 0, 2, 4, ...: a level of step s keeps ceil(n / s).
    level.dims[a] = (whole[2 * a + 1] - whole[2 * a] + step) / step;
    level.origin[a] = origin[a] + whole[2 * a] * h[a];
    level.spacing[a] = h[a] * step;
  }
  return level;
}

vtkSmartPointer<vtkImageData> LevelAsImage(vao::MomentLevel& level)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(static_cast<int>(level.dims[0]), static_cast<int>(level.dims[1]),
    static_cast<int>(level.dims[2]));
  image->SetOrigin(level.origin.data());
  image->SetSpacing(level.spacing.data());
  for (const auto& [name, values] :
    { std::make_pair("Mean", &level.mean), std::make_pair("Variance", &level.variance) })
  {
    // The level's block becomes the array's: no copy (a copy doubled the filter's peak).
    vtkNew<vtkFloatArray> array;
    array->SetName(name);
    const auto count = static_cast<vtkIdType>(values->size());
    array->SetArray(values->release(), count, 0, vtkAbstractArray::VTK_DATA_ARRAY_USER_DEFINED);
    array->SetArrayFreeFunction(&vao::recycleStorage);
    image->GetPointData()->AddArray(array);
  }
  image->GetPointData()->SetActiveScalars("Mean");
  return image;
}

vtkSmartPointer<vtkImageData> LevelPiece(
  vao::MomentLevel& level, const int whole[6], const int inputExt[6], const int piece[6], int step)
{
  vtkSmartPointer<vtkImageData> image = LevelAsImage(level);
  int levelExt[6], wanted[6];
  double origin[3];
  for (int a = 0; a < 3; ++a)
  {
    const int first = (inputExt[2 * a] - whole[2 * a]) / step; // in the whole level's grid
    levelExt[2 * a] = first;
    levelExt[2 * a + 1] = first + image->GetDimensions()[a] - 1;
    origin[a] = image->GetOrigin()[a] - first * image->GetSpacing()[a];
    wanted[2 * a] = (piece[2 * a] - whole[2 * a] + step - 1) / step;
    wanted[2 * a + 1] = std::min(levelExt[2 * a + 1], (piece[2 * a + 1] - whole[2 * a]) / step);
  }
  image->SetExtent(levelExt);
  image->SetOrigin(origin);
  auto part = vtkSmartPointer<vtkImageData>::New();
  if (vtkAmbientOcclusionExtents::EmptyExtent(wanted))
  {
    return part;
  }
  vtkAmbientOcclusionExtents::CopyRequestedExtent(image, part, wanted);
  // The whole level handed on as it is: its ranges as the build kept them, where it did.
  const bool wholeLevel = std::equal(wanted, wanted + 6, levelExt);
  for (const auto& [name, range] :
    { std::make_pair("Mean", level.meanRange), std::make_pair("Variance", level.varianceRange) })
  {
    if (wholeLevel && range.known)
    {
      vtkAmbientOcclusionRanges::CacheKnown(
        part->GetPointData()->GetArray(name), range.lowest, range.highest);
    }
  }
  return part;
}

} // namespace vtkAmbientOcclusionPyramidImages
