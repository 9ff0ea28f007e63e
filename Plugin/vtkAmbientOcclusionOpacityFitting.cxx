#include "vtkAmbientOcclusionOpacityFitting.h"

#include "vtkAmbientOcclusionFilterTable.h"
#include "vtkDataObject.h"
#include "vtkDataSetAttributes.h"
#include "vtkObjectFactory.h"
#include "vtkPVArrayInformation.h"
#include "vtkPVDataInformation.h"
#include "vtkPVDataSetAttributesInformation.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxyManager.h"
#include "vtkSMSessionProxyManager.h"
#include "vtkSMSourceProxy.h"
#include "vtkSMTransferFunctionProxy.h"

#include <cstring>
#include <vector>

namespace
{

/// The filters that read an opacity function, the property that holds it, and the methods
/// (if any) that must be chosen for it to be read.
struct Reader
{
  const char* Filter;
  const char* FunctionProperty;
  int FirstMethod; ///< -1: always read
  int LastMethod;
};

const Reader Readers[] = {
  // Transfer Function, Exact Rays and Rays
  { "VolumetricAmbientOcclusion", "OpacityFunction", 6, 8 },
  { "AmbientOcclusionShading", "OpacityTransferFunction", -1, -1 },
};

const Reader* ReaderOf(vtkSMProxy* proxy)
{
  return vtkAmbientOcclusionFilterEntry(Readers, proxy);
}

/// ParaView's new opacity function: (0, 0) to (1, 1), never fitted to any data.
bool Untouched(vtkSMProxy* function)
{
  if (!function->GetProperty("ScalarRangeInitialized") || !function->GetProperty("Points") ||
    vtkSMPropertyHelper(function, "ScalarRangeInitialized").GetAsInt() != 0)
  {
    return false;
  }
  const std::vector<double> points = vtkSMPropertyHelper(function, "Points").GetDoubleArray();
  const std::vector<double> fresh = { 0.0, 0.0, 0.5, 0.0, 1.0, 1.0, 0.5, 0.0 };
  return points == fresh;
}

/// The finite range of the filter's Scalars (its Component, else its first), updating its
/// input first; false when the input has no such array yet.
bool ScalarRange(vtkSMProxy* filter, double range[2])
{
  vtkSMPropertyHelper input(filter, "Input", true);
  auto* source = vtkSMSourceProxy::SafeDownCast(input.GetAsProxy());
  if (!source || !filter->GetProperty("Scalars"))
  {
    return false;
  }
  const int port = static_cast<int>(input.GetOutputPort());
  source->UpdatePipeline();
  vtkSMPropertyHelper scalars(filter, "Scalars");
  const char* name = scalars.GetInputArrayNameToProcess();
  vtkPVDataInformation* data = source->GetDataInformation(port);
  // No name: the active scalars (the default before the input had data).
  vtkPVArrayInformation* array = !data ? nullptr
    : name && *name
    ? data->GetArrayInformation(name, vtkDataObject::POINT)
    : data->GetPointDataInformation()->GetAttributeInformation(vtkDataSetAttributes::SCALARS);
  if (!array)
  {
    return false;
  }
  const int component =
    filter->GetProperty("Component") ? vtkSMPropertyHelper(filter, "Component").GetAsInt() : 0;
  array->GetComponentFiniteRange(
    component >= 0 && component < array->GetNumberOfComponents() ? component : 0, range);
  return range[0] <= range[1];
}

}

vtkStandardNewMacro(vtkAmbientOcclusionOpacityFitting);

void vtkAmbientOcclusionOpacityFitting::Fit(vtkSMProxy* filter)
{
  const Reader* reader = ReaderOf(filter);
  if (!reader || !filter->GetProperty(reader->FunctionProperty) ||
    (reader->FirstMethod >= 0 &&
      (vtkSMPropertyHelper(filter, "Method").GetAsInt() < reader->FirstMethod ||
        vtkSMPropertyHelper(filter, "Method").GetAsInt() > reader->LastMethod)))
  {
    return;
  }
  vtkSMProxy* function = vtkSMPropertyHelper(filter, reader->FunctionProperty).GetAsProxy();
  double range[2];
  if (!function || !Untouched(function) || !ScalarRange(filter, range))
  {
    return;
  }
  vtkSMTransferFunctionProxy::RescaleTransferFunction(function, range[0], range[1], false);
  vtkSMPropertyHelper(function, "ScalarRangeInitialized").Set(1);
  function->UpdateVTKObjects();
}

void vtkAmbientOcclusionOpacityFitting::Execute(vtkObject*, unsigned long event, void* callData)
{
  vtkSMProxy* proxy = nullptr;
  if (event == vtkCommand::RegisterEvent)
  {
    auto* info = static_cast<vtkSMProxyManager::RegisteredProxyInformation*>(callData);
    if (info && info->Type == vtkSMProxyManager::RegisteredProxyInformation::PROXY &&
      info->GroupName && std::strcmp(info->GroupName, "sources") == 0)
      proxy = info->Proxy;
  }
  else if (event == vtkCommand::PropertyModifiedEvent)
  {
    auto* info = static_cast<vtkSMProxyManager::ModifiedPropertyInformation*>(callData);
    const Reader* reader = info ? ReaderOf(info->Proxy) : nullptr;
    if (reader && info->PropertyName &&
      (std::strcmp(info->PropertyName, reader->FunctionProperty) == 0 ||
        std::strcmp(info->PropertyName, "Method") == 0 ||
        std::strcmp(info->PropertyName, "Scalars") == 0))
      proxy = info->Proxy;
  }
  vtkSMSessionProxyManager* pxm = proxy ? proxy->GetSessionProxyManager() : nullptr;
  if (pxm && !pxm->GetInLoadXMLState())
  {
    vtkAmbientOcclusionOpacityFitting::Fit(proxy);
  }
}
