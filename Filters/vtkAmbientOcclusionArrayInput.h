// Private helpers of the module's filters: the input arrays as the kernels read them (a
// volume's scalars, a surface's normals), the kernels' execution hooks, and the
// user-facing message of a failed kernel call. Not part of the module's public interface.
#ifndef vtkAmbientOcclusionArrayInput_h
#define vtkAmbientOcclusionArrayInput_h

#include "vtkAmbientOcclusionFrame.h"

#include "vao/AmbientOcclusion.h"

#include "vtkType.h"

#include <array>
#include <string>
#include <vector>

class vtkAlgorithm;
class vtkDataArray;
class vtkImageData;
class vtkPolyData;

namespace vtkAmbientOcclusionArrayInput
{

/// The input scalars as the kernels read them: in place when the array has the standard
/// layout (one component through the stride), unpacked to double otherwise.
struct ScalarVolume
{
  vao::VolumeView view;
  std::string name;
  std::vector<double> unpacked;
  /// Structured coordinates of the view's first voxel (the lower corner of the input's
  /// extent): a voxel index of the kernels becomes a voxel the user can find.
  std::array<int, 3> firstVoxel = { 0, 0, 0 };
  /// The image's frame (its direction matrix, a rotation): where the kernels' axis-aligned
  /// coordinates lie in the physical frame.
  vtkAmbientOcclusionFrame::Frame frame;
};

/// Takes the array the algorithm chose to process (`chosen`, from GetInputArrayToProcess;
/// the active point scalars when no array was named at all), checks it (numeric, point
/// data, a valid component, one tuple a point, an image whose direction matrix is a
/// rotation) and fills volume, its frame included. On failure returns false and says why in
/// `error`. NaN and infinite values are not looked for here: the kernels find them in
/// their first pass over the data, and KernelError names them.
bool PrepareScalars(vtkAlgorithm* algorithm, vtkDataArray* chosen, vtkImageData* input,
  int component, ScalarVolume& volume, std::string& error);

/// The surface's own point normals: its active normals, else a 3-component point array
/// named "Normals"; nullptr when it has neither.
vtkDataArray* GivenNormals(vtkPolyData* surface);

/// The unit normals of the surface's points as the surface kernels read them (3 doubles
/// a point, in the image's frame): its point normals turned into that frame, or without
/// them the gradient of `volume` (voxel 0 at `origin`) at `points` (3 doubles a point,
/// already in the image's frame), pointing towards lower values. A given normal that is
/// zero or not finite is replaced the same way (`replaced` counts them), and where the
/// gradient is zero too by the normal of the point's polygons. On failure (a point with
/// none of these) returns false and says why in `error`.
bool SurfaceNormals(vtkPolyData* surface, const std::vector<double>& points,
  const vtkAmbientOcclusionFrame::Frame& frame, const ScalarVolume& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing,
  std::vector<double>& normals, vtkIdType& replaced, std::string& error);

/// A surface's points and normals as the surface kernels read them: its float arrays in
/// place (what contours give), or a copy in doubles in the image's frame.
struct SurfacePoints
{
  vtkIdType count = 0;
  bool inPlace = false;
  const float* floatPoints = nullptr;
  const float* floatNormals = nullptr;
  std::vector<double> points, normals;
  vtkIdType replacedNormals = 0; ///< given normals that were zero or not finite

  /// kernel(points, normals) on whichever form is held: one call for either.
  template <class Kernel>
  vao::Status Run(Kernel&& kernel) const
  {
    return this->inPlace ? kernel(this->floatPoints, this->floatNormals)
                         : kernel(static_cast<const double*>(this->points.data()),
                             static_cast<const double*>(this->normals.data()));
  }
};

/// Fills `out` with the points of `surface`, which lie in `frame` (the image's, or the
/// identity where the surface ignored it): in place when its points and given normals are
/// float arrays and the frame is the identity, else (only when `needed`: a kernel will
/// run) a copy turned into the image's frame, with the normals of SurfaceNormals. False,
/// with the reason in `error`, when the given normals are fewer than the points or
/// SurfaceNormals fails.
bool ReadSurfacePoints(vtkPolyData* surface, const vtkAmbientOcclusionFrame::Frame& frame,
  const ScalarVolume& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, bool needed, SurfacePoints& out, std::string& error);

/// The error for a point array without one tuple for each of the data set's `points`
/// (VTK does not keep the two equal: a script or a reader can attach any array, and a
/// filter reading a short one would read past its end); empty when they match.
std::string PointCountError(vtkDataArray* array, vtkIdType points);

/// The error for a floating-point array with NaN or infinite values (how many, and the
/// first one's point); empty for an array without any (or of an integer type).
std::string NonFiniteError(vtkDataArray* array);

/// The one message of a failed kernel call on `scalars`, for the user: for non-finite
/// input, the array, how many such values it has and the first one's voxel in the input's
/// coordinates; otherwise "<failed>: <the kernel's reason>.". Empty when the call
/// succeeded or the user aborted it.
std::string KernelError(
  const vao::Status& status, const ScalarVolume& scalars, const std::string& failed);

} // namespace vtkAmbientOcclusionArrayInput

#endif
