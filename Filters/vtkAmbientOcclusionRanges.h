// Private helper of the module's filters: the ranges of the float arrays of a filter's
// output, computed in parallel (vao/ValueRanges.h) and stored where vtkDataArray caches
// them (COMPONENT_RANGE in PER_COMPONENT and PER_FINITE_COMPONENT, L2_NORM_RANGE and
// L2_NORM_FINITE_RANGE), so that GetRange and GetFiniteRange, which ParaView calls for
// every array after every update, answer at once instead of scanning on one thread.
// vtkAbstractArray::Modified() drops the cache, so an array changed later gets VTK's own
// ranges again.
#ifndef vtkAmbientOcclusionRanges_h
#define vtkAmbientOcclusionRanges_h

class vtkDataArray;
class vtkDataObject;

namespace vtkAmbientOcclusionRanges
{

/// Caches the ranges of one float array; leaves any other array, an array whose ranges
/// are already cached, and an array with a non-finite value (VTK's own rules for NaN and
/// infinity apply there) as they are.
void Cache(vtkDataArray* array);

/// Stores the range [lowest, highest] of a one-component float array whose values are all
/// finite, as a pass that wrote them kept it (vao::OutputRange).
void CacheKnown(vtkDataArray* array, double lowest, double highest);

/// Cache() for every point-data array of the output (a data set, or the data sets of a
/// composite output). The filters call it last in RequestData, inside their memory guard
/// (vtkAmbientOcclusionMemory::Guard): it allocates too.
void CacheOutput(vtkDataObject* output);

} // namespace vtkAmbientOcclusionRanges

#endif
