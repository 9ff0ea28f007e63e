// Private helper of the module's filters: allocation failure becomes an error message and
// an empty output instead of an uncaught std::bad_alloc, which would abort ParaView and
// lose the user's session. Not part of the module's public interface.
#ifndef vtkAmbientOcclusionMemory_h
#define vtkAmbientOcclusionMemory_h

#include "vtkType.h"

#include <functional>
#include <string>

class vtkAlgorithm;
class vtkDataArray;
class vtkDataObject;

namespace vtkAmbientOcclusionMemory
{

/// An allocation a filter could not make: its size and what it was for.
struct Shortage
{
  double bytes;
  std::string what;
};

/// Gives `array` `tuples` tuples (uninitialised, like SetNumberOfTuples), or throws
/// Shortage with the bytes it needed and `what` (e.g. "the AmbientOcclusion output").
void Allocate(vtkDataArray* array, vtkIdType tuples, const std::string& what);

/// Throws Shortage when `bytes` cannot be allocated now: for allocations VTK makes
/// itself (CopyAllocate), whose failure would abort.
void Reserve(double bytes, const std::string& what);

/// Runs a filter's RequestData body. A Shortage, or std::bad_alloc from anywhere inside
/// (VTK arrays, the kernels' buffers), becomes the error "Not enough memory for N MB (what);
/// <hint>" on the algorithm and an empty `output`; the pipeline stays usable. Returns
/// what the body returned, or 1 after a shortage (the error is the user's answer).
int Guard(vtkAlgorithm* algorithm, vtkDataObject* output, const char* hint,
  const std::function<int()>& body);

} // namespace vtkAmbientOcclusionMemory

#endif
