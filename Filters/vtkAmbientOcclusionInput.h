// Private helpers shared by the module's image filters: picking and checking the input
// array, presenting it to the kernels in place, and cropping the output to the requested
// extent. Not part of the module's public interface.
#ifndef vtkAmbientOcclusionInput_h
#define vtkAmbientOcclusionInput_h

#include "vao/AmbientOcclusion.h"
#include "vao/VarianceOcclusionMap.h"

#include "vtkSmartPointer.h"

#include <string>
#include <vector>

class vtkAlgorithm;
class vtkDataArray;
class vtkImageData;
class vtkInformation;
class vtkMultiProcessController;

namespace vtkAmbientOcclusionInput
{

/// The input scalars as the kernels read them: in place when the array has the standard
/// layout (one component through the stride), unpacked to double otherwise.
struct ScalarVolume
{
  vao::VolumeView view;
  std::string name;
  std::vector<double> unpacked;
};

/// Takes the array the algorithm chose to process (`chosen`, from GetInputArrayToProcess;
/// the active point scalars when no array was named at all), checks it (numeric, point
/// data, a valid component, no NaN or infinite voxels) and fills volume. On failure
/// returns false and says why in `error`.
bool PrepareScalars(vtkAlgorithm* algorithm, vtkDataArray* chosen, vtkImageData* input, int component,
  ScalarVolume& volume, std::string& error);

/// Checks that the whole extent is a 3-D volume (at least 2 voxels on every axis).
bool CheckWholeExtent(const int whole[6], std::string& error);

/// True when the extent holds no point (some max below its min).
bool EmptyExtent(const int ext[6]);

/// Points of the extent (0 when empty).
vtkIdType ExtentPoints(const int ext[6]);

/// Makes `output` the input restricted to `outExt` (a shallow copy when they are equal).
void CopyRequestedExtent(vtkImageData* input, vtkImageData* output, const int outExt[6]);

/// Input voxels between a pyramid level voxel and the farthest input voxel it depends on,
/// for `levels` levels: 2^levels (2^(levels+1) - 2 from half resolution).
int PyramidReach(int levels, bool half);

/// Input voxels between two voxels of the coarsest of `levels` levels: a piece's input
/// must start on a multiple of it so that its levels keep the whole volume's voxels.
int PyramidAlignment(int levels, bool half);

/// Piece `piece` of `pieces` of the whole extent, as ParaView splits it (block mode);
/// an empty extent when there are more pieces than voxels.
void PieceOfWhole(int piece, int pieces, const int whole[6], int ext[6]);

/// The piece of the whole extent asked of an output (UPDATE_PIECE_NUMBER of
/// UPDATE_NUMBER_OF_PIECES; the whole extent without them).
void RequestedPiece(vtkInformation* outputInformation, const int whole[6], int ext[6]);

/// The piece grown by reach[a] voxels per axis, clipped to the whole extent, its lower end
/// moved down to a multiple of `alignment` from the whole extent's start.
void GrowForPyramid(const int whole[6], const int piece[6], const int reach[3], int alignment, int ext[6]);

/// Asks the input for exactly `extent`, as one piece without ghost levels.
void RequestExactExtent(vtkInformation* inputInformation, const int extent[6]);

/// Asks the input for its whole extent, as one piece (global algorithms).
void RequestWholeExtent(vtkInformation* inputInformation);

/// The largest `value` over every process of the controller (a failure flag, a change).
/// Collective.
double GlobalMax(vtkMultiProcessController* controller, double value);

/// range = [min, max] over every process of the controller (unchanged with one process
/// or none). Collective.
void GlobalRange(vtkMultiProcessController* controller, double range[2]);

/// Distributed data held as blocks to distributed data as requested: every process holds
/// `held` (its block, any extent) and wants `wanted` (its requested extent, possibly
/// empty); each receives the parts of the others' blocks that overlap what it wants.
/// `output` gets the wanted extent with held's geometry and point arrays. Collective:
/// every process of the controller must call it.
void RedistributeExtents(vtkMultiProcessController* controller, vtkImageData* held,
  const int wanted[6], vtkImageData* output);

/// The kernel's execution hooks for an algorithm: its progress and abort flag.
vao::Execution ExecutionOf(vtkAlgorithm* algorithm);

/// World position of the first voxel of the image's extent.
std::array<double, 3> ExtentOrigin(vtkImageData* image);

/// Builds the moment pyramid of Penner & Mitchell from prepared scalars (PrepareScalars)
/// laid out on `input`'s grid. On failure returns false with the reason in `error`
/// (empty when the user aborted).
bool BuildPyramid(vtkAlgorithm* algorithm, const ScalarVolume& scalars, vtkImageData* input, int levels,
  bool startAtHalfResolution, std::vector<vao::MomentLevel>& pyramid, std::string& error);

/// The voxels of level `level` (built from the input extent inputExt, which keeps every
/// step-th input voxel from its start) whose input voxel lies in `piece`, as an image in
/// the whole level's grid (its extent and origin global). Takes over the level's storage.
vtkSmartPointer<vtkImageData> LevelPiece(
  vao::MomentLevel& level, const int whole[6], const int inputExt[6], const int piece[6], int step);

/// One pyramid level as image data with float arrays "Mean" and "Variance", which take
/// over the level's storage (the level's arrays are left empty).
vtkSmartPointer<vtkImageData> LevelAsImage(vao::MomentLevel& level);

} // namespace vtkAmbientOcclusionInput

#endif
