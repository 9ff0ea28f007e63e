// Private helpers of the module's filters: extent arithmetic (pieces, growth by a reach,
// intersections), the update requests made to the input, and cropping an image to an
// extent. Not part of the module's public interface.
#ifndef vtkAmbientOcclusionExtents_h
#define vtkAmbientOcclusionExtents_h

#include "vtkType.h"

#include <string>

class vtkImageData;
class vtkInformation;
class vtkInformationVector;

namespace vtkAmbientOcclusionExtents
{

/// Checks that the whole extent is a 3-D volume (at least 2 voxels on every axis).
bool CheckWholeExtent(const int whole[6], std::string& error);

/// The whole extent of an image algorithm's first input and the extent requested of its
/// output; false, with the reason in `error`, when the whole extent is not 3-D.
bool WholeAndRequestedExtent(vtkInformationVector* inputs, vtkInformationVector* outputs,
  int whole[6], int requested[6], std::string& error);

/// True when the extent holds no point (some max below its min).
bool EmptyExtent(const int ext[6]);

/// Points of the extent (0 when empty).
vtkIdType ExtentPoints(const int ext[6]);

/// a and b overlap in `common` (false when they do not, or either is empty).
bool IntersectExtents(const int a[6], const int b[6], int common[6]);

/// Grows ext by r[a] voxels on each axis a, clipped to whole.
void GrowExtent(int ext[6], const int r[3], const int whole[6]);

/// Makes `output` the input restricted to `outExt` (a shallow copy when they are equal).
void CopyRequestedExtent(vtkImageData* input, vtkImageData* output, const int outExt[6]);

/// Piece `piece` of `pieces` of the whole extent, as ParaView splits it (block mode);
/// an empty extent when there are more pieces than voxels.
void PieceOfWhole(int piece, int pieces, const int whole[6], int ext[6]);

/// The piece of the whole extent asked of an output (UPDATE_PIECE_NUMBER of
/// UPDATE_NUMBER_OF_PIECES; the whole extent without them).
void RequestedPiece(vtkInformation* outputInformation, const int whole[6], int ext[6]);

/// Input voxels between a pyramid level voxel and the farthest input voxel it depends on,
/// for `levels` levels: 2^levels (2^(levels+1) - 2 from half resolution).
int PyramidReach(int levels, bool half);

/// Input voxels between two voxels of the coarsest of `levels` levels: a piece's input
/// must start on a multiple of it so that its levels keep the whole volume's voxels.
int PyramidAlignment(int levels, bool half);

/// The piece grown by reach[a] voxels per axis, clipped to the whole extent, its lower end
/// moved down to a multiple of `alignment` from the whole extent's start.
void GrowForPyramid(
  const int whole[6], const int piece[6], const int reach[3], int alignment, int ext[6]);

/// The input extent from which a process samples the finer levels (0 .. levels - 2) of a
/// pyramid near the surface points of its piece, for surface queries at `offsetFactor`
/// times each level's kernel radius (and soft shadows): the piece grown by how far those
/// queries reach plus `slack` voxels (a surface piece's ghost cells) plus the levels'
/// own reach in the input, aligned like GrowForPyramid.
void GrowForSurfaceQueries(const int whole[6], const int piece[6], const double spacing[3],
  int levels, bool half, double offsetFactor, int slack, int ext[6]);

/// Asks the input for exactly `extent`, as one piece without ghost levels.
void RequestExactExtent(vtkInformation* inputInformation, const int extent[6]);

/// Asks the input for its whole extent, as one piece (global algorithms).
void RequestWholeExtent(vtkInformation* inputInformation);

/// Whether the input can be asked for a sub-extent: the first algorithm upstream that says
/// it can produce one (our filters, the XML readers, VTK's imaging filters) or, failing
/// that, the source itself. A reader that does not split (ParaView's MetaImage, NRRD)
/// cannot: asked for part of the volume as one piece it reads the file on every process
/// (and VTK 9.2's MetaImage reader crashes on compressed data). Filters in between that
/// pass extents along (a Calculator, a Programmable Filter) do not decide it. Data without
/// a pipeline behind it can, unless its information says it cannot (pieces of a composite
/// input, already spread over the processes).
bool CanProduceSubExtent(vtkInformation* inputInformation);

/// Asks the input for piece `piece` of `pieces` of its whole extent, without ghost levels:
/// from a source that does not split, the whole volume on one process and nothing on the
/// others, which then fetch what they need from it (CoverNeededExtent).
void RequestPieceOfWhole(vtkInformation* inputInformation, int piece, int pieces);

} // namespace vtkAmbientOcclusionExtents

#endif
