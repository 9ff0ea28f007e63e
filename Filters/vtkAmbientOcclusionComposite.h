// Private helpers of the module's filters: composite input (vtkMultiBlockDataSet,
// vtkPartitionedDataSet, vtkPartitionedDataSetCollection of images, on one process or
// spread over the processes of an MPI run) turned into the volumes they hold, and each
// volume handed to a filter's image path as one piece per process, as a pipeline hands a
// distributed image. Not part of the module's public interface.
//
// A volume is every image piece on one grid: the same spacing and direction, and origins
// one lattice apart (pieces that each start at extent 0 with their own origin, as Catalyst
// adaptors make them, count as well as pieces with shared origin and their own extents).
// In a vtkPartitionedDataSetCollection each partitioned data set holds its own volumes;
// elsewhere every leaf of the tree is considered together. Where pieces of one volume
// overlap (ghost layers), their common voxels must hold the same values.
#ifndef vtkAmbientOcclusionComposite_h
#define vtkAmbientOcclusionComposite_h

#include <functional>
#include <string>

class vtkAlgorithm;
class vtkImageData;
class vtkInformation;
class vtkInformationVector;
class vtkMultiProcessController;

namespace vtkAmbientOcclusionComposite
{

/// An input port that takes an image or a composite data set of images (the executive
/// then hands the composite data set itself, not its blocks one by one).
void AcceptImagesAndComposites(vtkInformation* portInformation);

/// Whether the data object on this input information is a composite data set.
bool IsComposite(vtkInformation* inputInformation);

/// An input port that takes a surface or a composite data set of surfaces.
void AcceptSurfacesAndComposites(vtkInformation* portInformation);

/// The output of a filter (its REQUEST_DATA_OBJECT): of the first input's type when that is
/// a composite data set, else a `single` (vtkImageData, vtkPolyData).
int RequestDataObject(
  vtkInformationVector** inputs, vtkInformationVector* outputs, const char* single);

/// A filter's image path: its RequestData given an image input (with WHOLE_EXTENT) and
/// an output information asking for one piece of it.
using ImagePath = std::function<int(vtkInformationVector** inputs, vtkInformationVector* outputs)>;

/// Runs an image filter on every volume of a composite input (port 0), collectively: each
/// process passes its pieces, the volume's voxels are moved so that each process holds
/// piece `rank` of the volume's whole extent (as ParaView splits it), `path` computes that
/// piece (fetching its halo from the neighbours, thresholds over the whole volume), and
/// the results are moved back onto the input's own pieces. `output` (a copy of the
/// input's structure) then holds each input piece with the filter's point arrays added.
/// On failure the output is empty on every process and `filter` reports why (the image
/// path reports its own errors). Returns 1, as RequestData does.
int ProduceEachVolume(vtkAlgorithm* filter, vtkMultiProcessController* controller,
  vtkInformationVector** inputs, vtkInformationVector* outputs, const ImagePath& path);

/// For a filter that samples a volume at a surface's points (port 0 the surface, port 1
/// the volume), either of which may be composite: the surface's blocks are taken as one
/// surface and the volume's pieces as one volume (piece `rank` of it on each process, as
/// ForEachVolume hands it), `path` runs once, collectively, and each block of the surface
/// gets its points' new arrays back. The output has the surface's type and structure. A
/// volume input that holds several volumes, or blocks that are not surfaces, are refused.
/// Returns 1, as RequestData does.
int ProduceOnSurface(vtkAlgorithm* filter, vtkMultiProcessController* controller,
  vtkInformationVector** inputs, vtkInformationVector* outputs, const ImagePath& path);

/// Calls `each` for every volume of a composite input, collectively, in the same order on
/// every process, with the number of volumes and an input information for the filter's
/// image path: the process's piece `rank` of the volume's whole extent (DATA_OBJECT),
/// WHOLE_EXTENT, ORIGIN, SPACING and DIRECTION, saying that the source cannot be asked for
/// another extent (the filter fetches what else it needs from the other processes). False,
/// with `error` (the same on every process), when the input holds something else than
/// images, or a volume's pieces leave a hole in its bounding extent; false, with `error`
/// empty, when `each` returned false on some process.
bool ForEachVolume(vtkMultiProcessController* controller, vtkInformation* input,
  const std::function<bool(int volume, int volumes, vtkInformation* information)>& each,
  std::string& error);

} // namespace vtkAmbientOcclusionComposite

#endif
