// Private helper of the module's filters, composed by each of them (they derive from four
// VTK superclasses): what every filter does around its own work, as named steps. Its
// threads and their progress and Abort (Execution), serial or distributed (Distributed),
// and its output under the memory guard with the ranges cached (ProduceOutput), so that each
// RequestData reads as one call. Extents grown by a reach are vtkAmbientOcclusionExtents'.
// Not part of the module's public interface.
#ifndef vtkAmbientOcclusionRequest_h
#define vtkAmbientOcclusionRequest_h

#include "vao/AmbientOcclusion.h"

#include <functional>
#include <string>

class vtkAlgorithm;
class vtkInformationVector;
class vtkMultiProcessController;

namespace vtkAmbientOcclusionRequest
{

/// The error for a NumberOfThreads below 0; empty for a valid one.
std::string ThreadsError(int threads);

/// The kernels' execution for an algorithm: `threads` (the filter's NumberOfThreads; 0: the
/// kernels' default), its progress and its abort flag. The kernels' progress p is reported
/// as from + (to - from) p, for a filter that runs them in stages.
vao::Execution Execution(vtkAlgorithm* algorithm, int threads, double from = 0.0, double to = 1.0);

/// Whether the filter runs distributed: a controller with more than one process.
bool Distributed(vtkMultiProcessController* controller);

/// Runs `produce` (the filter's own work, which fills output 0 of `outputs`), then caches
/// the ranges of the output's arrays (vtkAmbientOcclusionRanges::CacheOutput), both under
/// the memory guard (vtkAmbientOcclusionMemory::Guard): an allocation failure anywhere is
/// the error "Not enough memory ...; <memoryHint>" and an empty output, never an abort.
/// Under MPI the output's field data gets AmbientOcclusionBytesSent: the voxel and level
/// bytes this process sent to the others during the run (vtkAmbientOcclusionCollectives).
/// Returns what `produce` returned (1 after a shortage: the error is the answer).
int ProduceOutput(vtkAlgorithm* algorithm, vtkInformationVector* outputs, const char* memoryHint,
  const std::function<int()>& produce);

} // namespace vtkAmbientOcclusionRequest

#endif
