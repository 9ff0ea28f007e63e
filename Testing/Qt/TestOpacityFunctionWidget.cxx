// The Opacity Function list of Volumetric AO's Properties panel (pqOpacityFunctionWidget),
// offscreen in a builtin session with the plugin loaded: it lists the input's arrays and
// the arrays ParaView keeps an opacity function for; choosing one takes ParaView's own
// function of that array, which Apply hands to the filter (which then runs the method);
// a function set from Python shows in the list. Prints "FAILED: ..." and exits 1 on a
// failure. Usage: vaoOpacityWidgetTest PLUGIN
#include "pqOpacityFunctionWidget.h"

#include "pqApplicationCore.h"
#include "pqObjectBuilder.h"
#include "pqServer.h"
#include "pqServerResource.h"
#include "vtkPVArrayInformation.h"
#include "vtkPVDataInformation.h"
#include "vtkPVDataSetAttributesInformation.h"
#include "vtkSMPluginManager.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxyManager.h"
#include "vtkSMSessionProxyManager.h"
#include "vtkSMSourceProxy.h"
#include "vtkSMTransferFunctionManager.h"
#include "vtkSmartPointer.h"

#include <QApplication>
#include <QComboBox>

#include <iostream>

namespace
{

int Failures = 0;

void Check(bool ok, const std::string& what)
{
  std::cout << (ok ? "ok: " : "FAILED: ") << what << std::endl;
  Failures += ok ? 0 : 1;
}

vtkSmartPointer<vtkSMSourceProxy> NewSource(
  vtkSMSessionProxyManager* pxm, const char* group, const char* name)
{
  vtkSmartPointer<vtkSMSourceProxy> proxy;
  proxy.TakeReference(vtkSMSourceProxy::SafeDownCast(pxm->NewProxy(group, name)));
  return proxy;
}

} // namespace

int main(int argc, char* argv[])
{
  if (argc < 2)
  {
    std::cerr << "usage: vaoOpacityWidgetTest PLUGIN" << std::endl;
    return 2;
  }
  QApplication app(argc, argv);
  pqApplicationCore core(argc, argv);
  pqServer* server = core.getObjectBuilder()->createServer(pqServerResource("builtin:"));
  vtkSMProxyManager::GetProxyManager()->GetPluginManager()->LoadLocalPlugin(argv[1]);
  vtkSMSessionProxyManager* pxm = server->proxyManager();

  auto phantom = NewSource(pxm, "sources", "AmbientOcclusionHeadPhantom");
  Check(phantom != nullptr, "the plugin's proxies are defined");
  if (!phantom)
    return 1;
  const int dims[3] = { 24, 24, 24 };
  vtkSMPropertyHelper(phantom, "Dimensions").Set(dims, 3);
  phantom->UpdateVTKObjects();
  phantom->UpdatePipeline();
  auto filter = NewSource(pxm, "filters", "VolumetricAmbientOcclusion");
  vtkSMPropertyHelper(filter, "Input").Set(phantom, 0);
  vtkSMPropertyHelper(filter, "Method").Set(6); // Transfer Function
  vtkSMPropertyHelper(filter, "Radius").Set(2.0);
  filter->UpdateVTKObjects();

  vtkNew<vtkSMTransferFunctionManager> functions;
  vtkSMProxy* elsewhere = functions->GetOpacityTransferFunction("Elsewhere", pxm);
  vtkSMProperty* property = filter->GetProperty("OpacityFunction");
  pqOpacityFunctionWidget widget(filter, property);
  auto* list = widget.findChild<QComboBox*>("Arrays");
  const QStringList arrays = widget.arrays();
  Check(arrays == QStringList({ "Density", "Elsewhere" }),
    "the list offers the input's array and the array with a function: " +
      arrays.join(", ").toStdString());
  Check(!widget.function() && list && list->currentText() == "(choose an array)",
    "nothing is chosen before the user chooses");

  // Choosing "Density" in the list takes ParaView's function of Density, made as colouring
  // by the array would make it; Apply hands it to the filter.
  Q_EMIT list->activated(list->findText("Density"));
  vtkSMProxy* density = functions->GetOpacityTransferFunction("Density", pxm);
  Check(widget.function() == density && list->currentText() == "Density",
    "choosing Density takes ParaView's opacity transfer function of Density");
  Check(vtkSMPropertyHelper(property).GetAsProxy() == nullptr, "the filter keeps none until Apply");
  widget.apply();
  Check(vtkSMPropertyHelper(property).GetAsProxy() == density, "Apply sets OpacityFunction");
  const double points[8] = { -1000.0, 0.0, 0.5, 0.0, 2000.0, 1.0, 0.5, 0.0 };
  vtkSMPropertyHelper(density, "Points").Set(points, 8);
  density->UpdateVTKObjects();
  filter->UpdatePipeline();
  vtkPVArrayInformation* ao =
    filter->GetDataInformation(0)->GetPointDataInformation()->GetArrayInformation(
      "AmbientOcclusion");
  const double* range = ao ? ao->GetComponentRange(0) : nullptr;
  Check(range && range[0] >= 0.0 && range[1] <= 1.0 && range[1] > range[0],
    "the filter runs Transfer Function with the chosen function");

  // A function set elsewhere (Python, a state file) shows in the list.
  vtkSMPropertyHelper(property).Set(elsewhere);
  widget.reset();
  Check(widget.function() == elsewhere && list->currentText() == "Elsewhere",
    "a function set from Python shows as its array");
  vtkSMPropertyHelper(property).Set(static_cast<vtkSMProxy*>(nullptr));
  widget.reset();
  Check(!widget.function() && list->currentText() == "(choose an array)", "and none as none");
  std::cout << (Failures ? "FAILED" : "the opacity function list works") << std::endl;
  return Failures ? 1 : 0;
}
