// Private helper of vtkVolumetricAmbientOcclusion: Histogram CDF's thresholds from the
// value distribution of the whole data set (docs/methods.md section 8), never of one piece.
// Not part of the module's public interface.
#ifndef vtkAmbientOcclusionThresholds_h
#define vtkAmbientOcclusionThresholds_h

#include <functional>
#include <string>
#include <vector>

class vtkAlgorithm;
class vtkDataArray;
class vtkImageData;
class vtkMultiProcessController;
namespace vao
{
struct ValueScan;
struct VolumeView;
}

namespace vtkAmbientOcclusionThresholds
{

/// One process's part in Compute.
struct Piece
{
  /// Its input; null when it has none or failed before.
  const vao::VolumeView* volume = nullptr;
  /// The scan of its values (vao::scanValues: the caller has refused non-finite values
  /// with it); read only with a volume.
  const vao::ValueScan* scan = nullptr;
  /// The extent of `volume`.
  const int* inExt = nullptr;
  /// The extent it produces.
  const int* outExt = nullptr;
  /// The data set's whole extent.
  const int* whole = nullptr;
  /// Whether it failed before (then every process returns false).
  bool failed = false;
};

/// The thresholds of Histogram CDF with `bins` bins, from the whole data set: each voxel
/// of the whole extent is counted once, by the lowest process whose output extent holds
/// it, and the summaries are reduced over the controller's processes. Collective when the
/// controller has several processes: each must call it with its `piece` (a failed one
/// too). False, with the reason in `error`, when a process failed, or when the processes'
/// output extents do not cover the whole extent (the thresholds would not be the whole
/// data set's).
bool Compute(vtkMultiProcessController* controller, const Piece& piece, int bins,
  std::vector<double>& thresholds, std::string& error);

/// Thresholds kept on the array they were counted from, in its vtkInformation, like the
/// ranges vtkDataArray keeps there: another Histogram CDF run on the same array (another
/// radius, another filter on the same reader) takes them instead of counting its values
/// again. They hold while the array's MTime, the component and the number of bins stay:
/// whoever changes the values calls Modified(), as VTK requires. Recall gives false when
/// the array holds none for these.
bool Recall(vtkDataArray* array, int component, int bins, std::vector<double>& thresholds);
void Remember(vtkDataArray* array, int component, int bins, const std::vector<double>& thresholds);

/// The thresholds of the data set produced by `producer` (output `port`), read in `slabs`
/// slabs along z, each an update of the upstream pipeline with that extent, so that a
/// volume larger than memory is summarised slab by slab (two passes: the value range,
/// then the histogram). `view(image, volume, error)` gives the array of each slab. False, with the
/// reason in `error`, when a slab cannot be read or holds a NaN or infinite value.
bool ComputeInSlabs(vtkAlgorithm* producer, int port, int slabs, int bins,
  const std::function<bool(vtkImageData*, vao::VolumeView&, std::string&)>& view,
  std::vector<double>& thresholds, std::string& error);

/// The boxes of `ext` not covered by any extent of `others` (each 6 ints), as extents.
std::vector<std::vector<int>> SubtractExtents(
  const int ext[6], const std::vector<const int*>& others);

} // namespace vtkAmbientOcclusionThresholds

#endif
