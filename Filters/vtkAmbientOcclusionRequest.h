// Private helper of the module's filters: what every filter's RequestData does around its
// own work, as named steps, so that each RequestData reads as one call. Not part of the
// module's public interface.
#ifndef vtkAmbientOcclusionRequest_h
#define vtkAmbientOcclusionRequest_h

#include <functional>

class vtkAlgorithm;
class vtkInformationVector;

namespace vtkAmbientOcclusionRequest
{

/// Runs `produce` (the filter's own work, which fills output 0 of `outputs`), then caches
/// the ranges of the output's arrays (vtkAmbientOcclusionRanges::CacheOutput), both under
/// the memory guard (vtkAmbientOcclusionMemory::Guard): an allocation failure anywhere is
/// the error "Not enough memory ...; <memoryHint>" and an empty output, never an abort.
/// Returns what `produce` returned (1 after a shortage: the error is the answer).
int ProduceOutput(vtkAlgorithm* algorithm, vtkInformationVector* outputs, const char* memoryHint,
  const std::function<int()>& produce);

} // namespace vtkAmbientOcclusionRequest

#endif
