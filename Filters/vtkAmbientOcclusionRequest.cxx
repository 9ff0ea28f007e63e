#include "vtkAmbientOcclusionRequest.h"

#include "vtkAmbientOcclusionMemory.h"
#include "vtkAmbientOcclusionRanges.h"

#include "vtkDataObject.h"
#include "vtkInformationVector.h"

namespace vtkAmbientOcclusionRequest
{

int ProduceOutput(vtkAlgorithm* algorithm, vtkInformationVector* outputs, const char* memoryHint,
  const std::function<int()>& produce)
{
  vtkDataObject* output = vtkDataObject::GetData(outputs, 0);
  return vtkAmbientOcclusionMemory::Guard(algorithm, output, memoryHint,
    [&]() -> int
    {
      const int result = produce();
      vtkAmbientOcclusionRanges::CacheOutput(output);
      return result;
    });
}

} // namespace vtkAmbientOcclusionRequest
