#include "pqAmbientOcclusionLegends.h"

#include "pqApplicationCore.h"
#include "pqCoreUtilities.h"
#include "pqDataRepresentation.h"
#include "pqPipelineSource.h"
#include "pqPropertiesPanel.h"
#include "pqServerManagerModel.h"
#include "pqView.h"
#include "vtkSMPVRepresentationProxy.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"

#include <QTimer>
#include <QWidget>

#include <cstring>

pqAmbientOcclusionLegends::pqAmbientOcclusionLegends(QObject* parent)
  : QObject(parent)
{
}

void pqAmbientOcclusionLegends::startup()
{
  // A plugin named by PV_PLUGIN_PATH starts before the main window has its panels.
  QTimer::singleShot(0, this, &pqAmbientOcclusionLegends::followApply);
}

void pqAmbientOcclusionLegends::followApply()
{
  QWidget* window = pqCoreUtilities::mainWidget();
  pqPropertiesPanel* panel = window ? window->findChild<pqPropertiesPanel*>() : nullptr;
  if (panel)
  {
    // Connected after ParaView's own Apply behaviour, so this runs after its legends.
    QObject::connect(panel, SIGNAL(applied()), this, SLOT(hideUnmappedLegends()));
  }
  else if (++this->Tries < 100)
  {
    QTimer::singleShot(100, this, &pqAmbientOcclusionLegends::followApply);
  }
}

void pqAmbientOcclusionLegends::hideUnmappedLegends()
{
  pqServerManagerModel* model = pqApplicationCore::instance()->getServerManagerModel();
  for (pqDataRepresentation* representation : model->findItems<pqDataRepresentation*>())
  {
    vtkSMProxy* proxy = representation->getProxy();
    pqPipelineSource* source = representation->getInput();
    pqView* view = representation->getView();
    if (!source || !view || !representation->isVisible() ||
      std::strcmp(source->getProxy()->GetXMLName(), "AmbientOcclusionShading") != 0 ||
      !proxy->GetProperty("MapScalars") || vtkSMPropertyHelper(proxy, "MapScalars").GetAsInt())
    {
      continue;
    }
    if (auto* coloured = vtkSMPVRepresentationProxy::SafeDownCast(proxy))
    {
      coloured->SetScalarBarVisibility(view->getProxy(), false);
    }
  }
}
