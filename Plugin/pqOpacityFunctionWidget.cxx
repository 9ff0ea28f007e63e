#include "pqOpacityFunctionWidget.h"

#include "vtkNew.h"
#include "vtkPVArrayInformation.h"
#include "vtkPVDataInformation.h"
#include "vtkPVDataSetAttributesInformation.h"
#include "vtkSMInputProperty.h"
#include "vtkSMPropertyHelper.h"
#include "vtkSMProxy.h"
#include "vtkSMSessionProxyManager.h"
#include "vtkSMSourceProxy.h"
#include "vtkSMTransferFunctionManager.h"

#include <QComboBox>
#include <QHBoxLayout>
#include <QSignalBlocker>

#include <functional>

namespace
{

/// ParaView registers an array's opacity transfer function as "<array>.PiecewiseFunction".
const QString FunctionSuffix = QStringLiteral(".PiecewiseFunction");
const char* const FunctionGroup = "piecewise_functions";

/// A combo box that asks for its items just before it opens.
class RefreshingComboBox : public QComboBox
{
public:
  RefreshingComboBox(std::function<void()> refresh, QWidget* parent)
    : QComboBox(parent)
    , Refresh(std::move(refresh))
  {
  }
  void showPopup() override
  {
    this->Refresh();
    this->QComboBox::showPopup();
  }

private:
  std::function<void()> Refresh;
};

/// The point arrays of the proxy's input, then those ParaView keeps an opacity function for.
QStringList ArraysOf(vtkSMProxy* proxy)
{
  QStringList names;
  auto* input = vtkSMInputProperty::SafeDownCast(proxy->GetProperty("Input"));
  auto* source = input ? vtkSMSourceProxy::SafeDownCast(input->GetProxy(0)) : nullptr;
  if (source)
  {
    vtkPVDataInformation* data = source->GetDataInformation(input->GetOutputPortForConnection(0));
    vtkPVDataSetAttributesInformation* points = data ? data->GetPointDataInformation() : nullptr;
    for (int i = 0; points && i < points->GetNumberOfArrays(); ++i)
      names.append(QString::fromUtf8(points->GetArrayInformation(i)->GetName()));
  }
  vtkSMSessionProxyManager* pxm = proxy->GetSessionProxyManager();
  for (unsigned int i = 0; i < pxm->GetNumberOfProxies(FunctionGroup); ++i)
  {
    const QString name = QString::fromUtf8(pxm->GetProxyName(FunctionGroup, i));
    if (name.endsWith(FunctionSuffix))
      names.append(name.left(name.size() - FunctionSuffix.size()));
  }
  names.removeDuplicates();
  return names;
}

} // namespace

//------------------------------------------------------------------------------
pqOpacityFunctionWidget::pqOpacityFunctionWidget(
  vtkSMProxy* proxy, vtkSMProperty* property, QWidget* parent)
  : Superclass(proxy, parent)
  , List(new RefreshingComboBox([this] { this->refresh(); }, this))
{
  this->setProperty(property);
  this->List->setObjectName("Arrays");
  this->List->setToolTip(tr("The array whose opacity transfer function (as the Color Map Editor "
                            "edits it) occludes"));
  auto* layout = new QHBoxLayout(this);
  layout->setContentsMargins(0, 0, 0, 0);
  layout->addWidget(this->List);
  this->Function = vtkSMPropertyHelper(property).GetAsProxy();
  this->refresh();
  QObject::connect(this->List, QOverload<int>::of(&QComboBox::activated),
    [this](int index) { this->chooseArray(this->List->itemData(index).toString()); });
  this->addPropertyLink(this, "function", SIGNAL(functionChanged()), property);
}

//------------------------------------------------------------------------------
pqOpacityFunctionWidget::~pqOpacityFunctionWidget() = default;

//------------------------------------------------------------------------------
pqSMProxy pqOpacityFunctionWidget::function() const
{
  return this->Function;
}

//------------------------------------------------------------------------------
void pqOpacityFunctionWidget::setFunction(pqSMProxy function)
{
  if (this->Function != function)
  {
    this->Function = function;
    this->refresh();
    Q_EMIT this->functionChanged();
  }
}

//------------------------------------------------------------------------------
QStringList pqOpacityFunctionWidget::arrays()
{
  this->refresh();
  QStringList names;
  for (int i = 0; i < this->List->count(); ++i)
  {
    if (!this->List->itemData(i).toString().isEmpty())
      names.append(this->List->itemData(i).toString());
  }
  return names;
}

//------------------------------------------------------------------------------
void pqOpacityFunctionWidget::chooseArray(const QString& array)
{
  if (array.isEmpty())
    return;
  vtkNew<vtkSMTransferFunctionManager> manager;
  const QByteArray name = array.toUtf8();
  this->setFunction(
    manager->GetOpacityTransferFunction(name.constData(), this->proxy()->GetSessionProxyManager()));
}

//------------------------------------------------------------------------------
void pqOpacityFunctionWidget::refresh()
{
  const QSignalBlocker quiet(this->List);
  this->List->clear();
  vtkSMSessionProxyManager* pxm = this->proxy()->GetSessionProxyManager();
  const char* chosen = this->Function ? pxm->GetProxyName(FunctionGroup, this->Function) : nullptr;
  const QString chosenName = chosen ? QString::fromUtf8(chosen) : QString();
  if (!this->Function)
    this->List->addItem(tr("(choose an array)"), QString());
  else if (!chosenName.endsWith(FunctionSuffix))
    this->List->addItem(tr("(a function of no array)"), QString());
  for (const QString& array : ArraysOf(this->proxy()))
  {
    this->List->addItem(array, array);
    if (chosenName == array + FunctionSuffix)
      this->List->setCurrentIndex(this->List->count() - 1);
  }
}
