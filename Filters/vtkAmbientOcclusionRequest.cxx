#include "vtkAmbientOcclusionRequest.h"

#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionMemory.h"
#include "vtkAmbientOcclusionRanges.h"

#include "vtkAlgorithm.h"
#include "vtkDataObject.h"
#include "vtkFieldData.h"
#include "vtkIdTypeArray.h"
#include "vtkInformationVector.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"

#include <sstream>

namespace vtkAmbientOcclusionRequest
{

vao::Execution Execution(vtkAlgorithm* algorithm, int threads, double from, double to)
{
  vao::Execution execution;
  execution.threads = threads;
  execution.progress = [algorithm, from, to](double p)
  { algorithm->UpdateProgress(from + (to - from) * p); };
  execution.abortRequested = [algorithm] { return algorithm->GetAbortExecute() != 0; };
  return execution;
}

std::string ThreadsError(int threads)
{
  if (threads >= 0)
  {
    return {};
  }
  std::ostringstream why;
  why << "NumberOfThreads must be 0 (the cores available, divided among the MPI ranks of the node) "
         "or positive (got "
      << threads << ").";
  return why.str();
}

bool Distributed(vtkMultiProcessController* controller)
{
  return controller && controller->GetNumberOfProcesses() > 1;
}

int ProduceOutput(vtkAlgorithm* algorithm, vtkInformationVector* outputs, const char* memoryHint,
  const std::function<int()>& produce)
{
  vtkDataObject* output = vtkDataObject::GetData(outputs, 0);
  return vtkAmbientOcclusionMemory::Guard(algorithm, output, memoryHint,
    [&]() -> int
    {
      const vtkIdType sentBefore = vtkAmbientOcclusionCollectives::BytesSent();
      const int result = produce();
      vtkAmbientOcclusionRanges::CacheOutput(output);
      if (Distributed(vtkMultiProcessController::GetGlobalController()) && output)
      {
        vtkNew<vtkIdTypeArray> sent; // what the halos and pieces of this run cost this process
        sent->SetName("AmbientOcclusionBytesSent");
        sent->InsertNextValue(vtkAmbientOcclusionCollectives::BytesSent() - sentBefore);
        output->GetFieldData()->AddArray(sent);
      }
      return result;
    });
}

} // namespace vtkAmbientOcclusionRequest
