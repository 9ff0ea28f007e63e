#include "vtkAmbientOcclusionDisplayDefaults.h"
#include "vtkAmbientOcclusionOpacityFitting.h"

#include "vtkAmbientOcclusionFilterTable.h"
#include "vtkDataObject.h"
#include "vtkObjectFactory.h"
#include "vtkPVDataInformation.h"
#include "vtkSMPVRepresentationProxy.h"
#include "vtkSMProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxyManager.h"
#include "vtkSMSessionProxyManager.h"
#include "vtkSMSourceProxy.h"
#include "vtkSMTransferFunctionManager.h"
#include "vtkSMTransferFunctionProxy.h"
#include "vtkSmartPointer.h"
#include "vtkTimeStamp.h"

#include <algorithm>
#include <cstring>
#include <string>

namespace
{

/// What a filter's result is coloured by when it is first shown.
struct Display
{
  const char* Filter;       ///< the proxy's XML name
  const char* NameProperty; ///< the property that names the array, or nullptr
  const char* Arrays[2];    ///< the arrays to colour by, the first present wins
  bool Colours;             ///< the array holds colours: no colour map
};

const Display Displays[] = {
  { "VolumetricAmbientOcclusion", "OutputArrayName", { "AmbientOcclusion", nullptr }, false },
  { "OcclusionSweeping", nullptr, { "AmbientOcclusion", nullptr }, false },
  { "IsosurfaceAmbientOcclusion", nullptr, { "AmbientOcclusion", nullptr }, false },
  { "ProbeOutsideSurface", nullptr, { "AmbientOcclusion", nullptr }, false },
  { "AmbientOcclusionShading", nullptr, { "ShadedRGBA", "ShadedRGB" }, true },
};

const Display* DisplayOf(vtkSMProxy* proxy)
{
  return vtkAmbientOcclusionFilterEntry(Displays, proxy);
}

/// The array of `display` that the producer's output has, or "".
std::string ArrayToColour(const Display& display, vtkSMSourceProxy* producer, int port)
{
  vtkPVDataInformation* info = producer->GetDataInformation(port);
  if (!info)
  {
    return {};
  }
  if (display.NameProperty)
  {
    const char* name = vtkSMPropertyHelper(producer, display.NameProperty).GetAsString();
    return name && info->GetArrayInformation(name, vtkDataObject::POINT) ? name : "";
  }
  for (const char* name : display.Arrays)
  {
    if (name && info->GetArrayInformation(name, vtkDataObject::POINT))
    {
      return name;
    }
  }
  return {};
}

/// Openness is in [0, 1] whatever the data: a fixed grey map keeps results comparable.
void GreyOverUnitRange(vtkSMProxy* lut)
{
  vtkSMTransferFunctionProxy::ApplyPreset(lut, "Grayscale", /*rescale=*/false);
  vtkSMTransferFunctionProxy::RescaleTransferFunction(lut, 0.0, 1.0, /*extend=*/false);
  lut->UpdateVTKObjects();
}

/// The volume's opacity is the RGBA's alpha (0-255) as it is, whatever the data range.
void AlphaAsOpacity(vtkSMProxy* lut)
{
  vtkSMPropertyHelper(lut, "AutomaticRescaleRangeMode").Set(vtkSMTransferFunctionManager::NEVER);
  lut->UpdateVTKObjects();
  if (vtkSMProxy* opacity = vtkSMPropertyHelper(lut, "ScalarOpacityFunction", true).GetAsProxy())
  {
    const double points[] = { 0.0, 0.0, 0.5, 0.0, 255.0, 1.0, 0.5, 0.0 };
    vtkSMPropertyHelper(opacity, "Points").Set(points, 8);
    opacity->UpdateVTKObjects();
  }
}

}

vtkStandardNewMacro(vtkAmbientOcclusionDisplayDefaults);

void vtkAmbientOcclusionDisplayDefaults::Install()
{
  static bool installed = false;
  if (installed || !vtkSMProxyManager::IsInitialized())
  {
    return;
  }
  installed = true;
  // Every session's proxy manager forwards its registrations and property changes to
  // this one.
  vtkSMProxyManager* manager = vtkSMProxyManager::GetProxyManager();
  vtkNew<vtkAmbientOcclusionDisplayDefaults> display;
  manager->AddObserver(vtkCommand::RegisterEvent, display);
  vtkNew<vtkAmbientOcclusionOpacityFitting> fitting;
  manager->AddObserver(vtkCommand::RegisterEvent, fitting);
  manager->AddObserver(vtkCommand::PropertyModifiedEvent, fitting);
}

void vtkAmbientOcclusionDisplayDefaults::Execute(vtkObject*, unsigned long event, void* callData)
{
  auto* info = static_cast<vtkSMProxyManager::RegisteredProxyInformation*>(callData);
  if (event != vtkCommand::RegisterEvent || !info || !info->Proxy ||
    info->Type != vtkSMProxyManager::RegisteredProxyInformation::PROXY || !info->GroupName)
  {
    return;
  }
  if (std::strcmp(info->GroupName, "lookup_tables") == 0)
  {
    vtkTimeStamp now;
    now.Modified();
    this->NewMaps.erase(std::remove_if(this->NewMaps.begin(), this->NewMaps.end(),
                          [](const NewMap& map) { return !map.first; }),
      this->NewMaps.end());
    this->NewMaps.emplace_back(info->Proxy, now.GetMTime());
    return;
  }
  vtkSMSessionProxyManager* pxm = info->Proxy->GetSessionProxyManager();
  if (std::strcmp(info->GroupName, "representations") == 0 &&
    vtkSMPVRepresentationProxy::SafeDownCast(info->Proxy) && pxm && !pxm->GetInLoadXMLState())
  {
    this->Apply(info->Proxy);
  }
}

bool vtkAmbientOcclusionDisplayDefaults::MadeSince(vtkSMProxy* lut, vtkMTimeType time) const
{
  for (const NewMap& map : this->NewMaps)
  {
    if (map.first == lut)
    {
      return map.second > time;
    }
  }
  return false;
}

void vtkAmbientOcclusionDisplayDefaults::Apply(vtkSMProxy* representation)
{
  vtkSMProperty* inputProperty = representation->GetProperty("Input");
  if (!inputProperty || !representation->GetProperty("ColorArrayName"))
  {
    return;
  }
  vtkSMPropertyHelper input(inputProperty);
  auto* producer = vtkSMSourceProxy::SafeDownCast(input.GetAsProxy());
  const Display* display = DisplayOf(producer);
  if (!display)
  {
    return;
  }
  const std::string array = ArrayToColour(*display, producer, input.GetOutputPort());
  // The member functions: ParaView 5.13 has no static SetScalarColoring.
  auto* coloured = vtkSMPVRepresentationProxy::SafeDownCast(representation);
  if (array.empty() || !coloured ||
    !coloured->SetScalarColoring(array.c_str(), vtkDataObject::POINT))
  {
    return;
  }
  // A map made while this representation was set up (Show() sets its input first) is
  // ours to choose; one that existed before may carry the user's edits.
  vtkSMProxy* lut = vtkSMPropertyHelper(representation, "LookupTable", true).GetAsProxy();
  const bool newMap = lut && this->MadeSince(lut, inputProperty->GetMTime());
  if (display->Colours)
  {
    vtkSMPropertyHelper(representation, "MapScalars").Set(0);
    if (newMap)
    {
      AlphaAsOpacity(lut);
    }
  }
  else if (newMap)
  {
    GreyOverUnitRange(lut);
  }
  representation->UpdateVTKObjects();
}

namespace
{
/// The plugin's library is loaded once per process, after the proxy manager exists.
const struct InstallOnLoad
{
  InstallOnLoad() { vtkAmbientOcclusionDisplayDefaults::Install(); }
} installOnLoad;
}
