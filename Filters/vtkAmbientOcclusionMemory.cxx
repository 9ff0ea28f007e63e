#include "vtkAmbientOcclusionMemory.h"

#include "vtkAlgorithm.h"
#include "vtkDataArray.h"
#include "vtkDataObject.h"
#include "vtkObject.h"

#include "vao/Storage.h"

#include <cstdlib>
#include <iomanip>
#include <new>
#include <sstream>

namespace vtkAmbientOcclusionMemory
{

void Allocate(vtkDataArray* array, vtkIdType tuples, const std::string& what)
{
  // Not SetNumberOfTuples: a VTK built without NDEBUG (Debian's) aborts when that fails.
  // The block is ours to allocate (vao/Storage.h: huge pages where large), then the
  // array's, freed with recycleStorage (kept for the next output of its size).
  const vtkIdType values = tuples * array->GetNumberOfComponents();
  if (values <= 0)
  {
    array->SetNumberOfTuples(0);
    return;
  }
  const double bytes = static_cast<double>(values) * array->GetDataTypeSize();
  void* block = bytes < 9e18 ? vao::allocateStorage(static_cast<std::size_t>(bytes)) : nullptr;
  if (!block)
  {
    throw Shortage{ bytes, what };
  }
  array->SetVoidArray(block, values, 0, vtkAbstractArray::VTK_DATA_ARRAY_USER_DEFINED);
  array->SetArrayFreeFunction(&vao::recycleStorage);
}

void Reserve(double bytes, const std::string& what)
{
  void* probe =
    bytes < 9e18 ? std::malloc(static_cast<std::size_t>(bytes > 0 ? bytes : 1)) : nullptr;
  if (!probe)
  {
    throw Shortage{ bytes, what };
  }
  std::free(probe);
}

int Guard(vtkAlgorithm* algorithm, vtkDataObject* output, const char* hint,
  const std::function<int()>& body)
{
  std::ostringstream why;
  try
  {
    return body();
  }
  catch (const Shortage& shortage)
  {
    why << "Not enough memory for " << std::fixed << std::setprecision(0)
        << shortage.bytes / (1024.0 * 1024.0) << " MB (" << shortage.what << "); " << hint;
  }
  catch (const std::bad_alloc&)
  {
    why << "Not enough memory for the filter's working buffers; " << hint;
  }
  if (output)
  {
    output->Initialize();
  }
  vtkErrorWithObjectMacro(algorithm, << why.str());
  return 1;
}

} // namespace vtkAmbientOcclusionMemory
