// Private helpers of the module's filters: building the moment pyramid of Penner &
// Mitchell from an input image, and its levels as (pieces of) images. Not part of the
// module's public interface.
#ifndef vtkAmbientOcclusionPyramidImages_h
#define vtkAmbientOcclusionPyramidImages_h

#include "vtkAmbientOcclusionArrayInput.h"

#include "vao/VarianceOcclusionMap.h"

#include "vtkSmartPointer.h"

#include <array>
#include <string>
#include <vector>

class vtkImageData;
class vtkObject;

namespace vtkAmbientOcclusionPyramidImages
{

/// World position of the first voxel of the image's extent.
std::array<double, 3> ExtentOrigin(vtkImageData* image);

/// Builds the moment pyramid from prepared scalars (PrepareScalars) laid out on `input`'s
/// grid. On failure returns false with the reason in `error` (empty when the user
/// aborted).
bool BuildPyramid(const vtkAmbientOcclusionArrayInput::ScalarVolume& scalars, vtkImageData* input,
  const vao::PyramidParameters& parameters, const vao::Execution& execution,
  std::vector<vao::MomentLevel>& pyramid, std::string& error);

/// The same as a SurfacePyramid (level 0 built where the surface queries reach it), which
/// reads `scalars` again whenever a query builds tiles.
bool BuildPyramid(const vtkAmbientOcclusionArrayInput::ScalarVolume& scalars, vtkImageData* input,
  const vao::PyramidParameters& parameters, const vao::Execution& execution,
  vao::SurfacePyramid& pyramid, std::string& error);

/// Warns, as `owner`, when the levels' float32 means resolve the values coarsely
/// (vao::meanResolution of the coarsest level past vao::kCoarseMeanResolution: values far
/// from 0 against their spread).
void WarnOfCoarseMeans(vtkObject* owner, const std::vector<vao::MomentLevel>& levels);

/// The geometry (dims, origin, spacing) of the whole volume's level that keeps every
/// step-th voxel of `volume`'s grid from the start of its whole extent; no values.
vao::MomentLevel WholeLevelGeometry(vtkImageData* volume, const int whole[6], int step);

/// One pyramid level as image data with float arrays "Mean" and "Variance", which take
/// over the level's storage (the level's arrays are left empty).
vtkSmartPointer<vtkImageData> LevelAsImage(vao::MomentLevel& level);

/// The voxels of a level (built from the input extent inputExt, which keeps every
/// step-th input voxel from its start) whose input voxel lies in `piece`, as an image in
/// the whole level's grid (its extent and origin global). Takes over the level's storage.
vtkSmartPointer<vtkImageData> LevelPiece(
  vao::MomentLevel& level, const int whole[6], const int inputExt[6], const int piece[6], int step);

} // namespace vtkAmbientOcclusionPyramidImages

#endif
