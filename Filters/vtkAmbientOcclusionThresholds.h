// Private helper of vtkVolumetricAmbientOcclusion: Histogram CDF's thresholds from the
// value distribution of the whole data set (docs/methods.md section 8), never of one piece.
// Not part of the module's public interface.
#ifndef vtkAmbientOcclusionThresholds_h
#define vtkAmbientOcclusionThresholds_h

#include <functional>
#include <string>
#include <vector>

class vtkAlgorithm;
class vtkImageData;
class vtkMultiProcessController;
namespace vao
{
struct ValueScan;
struct VolumeView;
}

namespace vtkAmbientOcclusionThresholds
{

/// The thresholds of Histogram CDF with `bins` bins. Each process passes its input
/// (`volume`, extent `inExt`; null when it has none or failed before), the scan of its
/// values (vao::scanValues: the caller has refused non-finite values with it) and the
/// extent it produces (`outExt`); each voxel of the whole extent is counted once, by the lowest
/// process whose output extent holds it, and the summaries are reduced over the
/// controller's processes. Collective when the controller has several processes: each
/// must call it, `failed` saying whether it failed before (then every process returns
/// false). False, with the reason in `error`, when the processes' output extents do not
/// cover the whole extent (the thresholds would not be the whole data set's).
bool Compute(vtkMultiProcessController* controller, const vao::VolumeView* volume, const vao::ValueScan& scan,
  const int inExt[6],
  const int outExt[6], const int whole[6], int bins, bool failed, std::vector<double>& thresholds,
  std::string& error);

/// The thresholds of the data set produced by `producer` (output `port`), read in `slabs`
/// slabs along z, each an update of the upstream pipeline with that extent, so that a
/// volume larger than memory is summarised slab by slab (two passes: the value range,
/// then the histogram). `view(image, volume, error)` gives the array of each slab. False, with the
/// reason in `error`, when a slab cannot be read or holds a NaN or infinite value.
bool ComputeInSlabs(vtkAlgorithm* producer, int port, int slabs, int bins,
  const std::function<bool(vtkImageData*, vao::VolumeView&, std::string&)>& view,
  std::vector<double>& thresholds, std::string& error);

/// The boxes of `ext` not covered by any extent of `others` (each 6 ints), as extents.
std::vector<std::vector<int>> SubtractExtents(const int ext[6], const std::vector<const int*>& others);

} // namespace vtkAmbientOcclusionThresholds

#endif
