#include "vtkAmbientOcclusionRanges.h"

#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkDataSet.h"
#include "vtkFloatArray.h"
#include "vtkInformation.h"
#include "vtkInformationDoubleVectorKey.h"
#include "vtkInformationInformationVectorKey.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkPointData.h"

#include "vao/ValueRanges.h"

namespace vtkAmbientOcclusionRanges
{

namespace
{

/// Where vtkDataArray caches ranges: every value is finite, so the range and the finite
/// range are the same.
void Store(vtkFloatArray* values, const vao::ValueRanges& ranges)
{
  const int components = values->GetNumberOfComponents();
  vtkInformation* info = values->GetInformation();
  for (vtkInformationInformationVectorKey* key :
    { vtkAbstractArray::PER_COMPONENT(), vtkAbstractArray::PER_FINITE_COMPONENT() })
  {
    vtkNew<vtkInformationVector> perComponent;
    perComponent->SetNumberOfInformationObjects(components);
    for (int c = 0; c < components; ++c)
    {
      perComponent->GetInformationObject(c)->Set(
        vtkDataArray::COMPONENT_RANGE(), ranges.components.data() + 2 * c, 2);
    }
    info->Set(key, perComponent);
  }
  if (components > 1)
  {
    info->Set(vtkDataArray::L2_NORM_RANGE(), ranges.norm, 2);
    info->Set(vtkDataArray::L2_NORM_FINITE_RANGE(), ranges.norm, 2);
  }
}

} // namespace

void Cache(vtkDataArray* array)
{
  auto* values = vtkFloatArray::SafeDownCast(array);
  if (!values || values->GetInformation()->Has(vtkAbstractArray::PER_COMPONENT()))
  {
    return;
  }
  const int components = values->GetNumberOfComponents();
  vao::ValueRanges ranges;
  if (!vao::computeFiniteValueRanges(
        values->GetPointer(0), values->GetNumberOfTuples(), components, ranges))
  {
    return;
  }
  Store(values, ranges);
}

void CacheKnown(vtkDataArray* array, double lowest, double highest)
{
  auto* values = vtkFloatArray::SafeDownCast(array);
  if (!values || values->GetNumberOfComponents() != 1 || values->GetNumberOfTuples() == 0)
  {
    return;
  }
  vao::ValueRanges ranges;
  ranges.components = { lowest, highest };
  Store(values, ranges);
}

void CacheOutput(vtkDataObject* output)
{
  auto cacheSet = [](vtkDataSet* set)
  {
    vtkPointData* pd = set ? set->GetPointData() : nullptr;
    for (int i = 0; pd && i < pd->GetNumberOfArrays(); ++i)
    {
      Cache(pd->GetArray(i));
    }
  };
  if (auto* composite = vtkCompositeDataSet::SafeDownCast(output))
  {
    for (vtkDataSet* set : vtkCompositeDataSet::GetDataSets<vtkDataSet>(composite))
    {
      cacheSet(set);
    }
    return;
  }
  cacheSet(vtkDataSet::SafeDownCast(output));
}

} // namespace vtkAmbientOcclusionRanges
