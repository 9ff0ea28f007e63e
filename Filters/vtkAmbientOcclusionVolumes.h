// Private helpers of the module's filters: the volumes a composite data set of images
// holds (see vtkAmbientOcclusionComposite for what counts as one volume), found by every
// process together, and one volume gathered as each process's piece of its whole extent.
// Not part of the module's public interface.
#ifndef vtkAmbientOcclusionVolumes_h
#define vtkAmbientOcclusionVolumes_h

#include "vtkSmartPointer.h"

#include <array>
#include <string>
#include <vector>

class vtkCompositeDataIterator;
class vtkCompositeDataSet;
class vtkDataObject;
class vtkImageData;
class vtkInformation;
class vtkMultiProcessController;

namespace vtkAmbientOcclusionVolumes
{

/// One volume: pieces on one grid, in the index space of its first piece's origin.
struct Volume
{
  double scope; // the partitioned data set of a collection, else 0
  double origin[3], spacing[3], direction[9];
  double arrays; // a digest of the point arrays every piece carries
  int whole[6];
};

/// A composite data set's leaves, in traversal order, and its volumes.
struct Volumes
{
  std::vector<vtkDataObject*> leaves;         // every non-empty leaf, in traversal order
  std::vector<int> leafPiece;                 // its index among this process's image pieces, or -1
  std::vector<vtkImageData*> pieces;          // this process's image pieces with voxels
  std::vector<int> pieceVolume;               // the volume of each
  std::vector<std::array<int, 3>> pieceShift; // its extent's shift into the volume's indices
  std::vector<Volume> volumes;
};

/// An iterator over the leaves of `input` that hold something, in traversal order.
vtkSmartPointer<vtkCompositeDataIterator> LeafIterator(vtkCompositeDataSet* input);

/// The volumes of `input`, the same on every process (in the collection's order, then in
/// the order first met). False, with `error` (the same on every process), when a leaf is
/// not an image or the pieces of one grid carry different point arrays. Collective.
bool Find(vtkMultiProcessController* controller, vtkCompositeDataSet* input, Volumes& found,
  std::string& error);

/// Volume v as this process's piece of its whole extent (ParaView's split), with the
/// input information of an image path that reads it (DATA_OBJECT, WHOLE_EXTENT, ORIGIN,
/// SPACING, DIRECTION; it cannot be asked for another extent). False, with `error`, when
/// the pieces leave a voxel of the volume's bounding extent without a value. Collective.
bool GatherPiece(vtkMultiProcessController* controller, const Volumes& found, int v,
  vtkInformation* information, std::string& error);

} // namespace vtkAmbientOcclusionVolumes

#endif
