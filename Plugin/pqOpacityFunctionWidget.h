// The Opacity Function property of Volumetric Ambient Occlusion in ParaView's Properties
// panel: a list of arrays. Choosing one takes ParaView's opacity transfer function of that
// array, the one the Color Map Editor edits and the volume representation uses (made as
// colouring by the array would make it), so the user never retypes points. The list holds
// the input's point arrays and every array ParaView already keeps an opacity function for;
// it is read again each time it opens.
#ifndef pqOpacityFunctionWidget_h
#define pqOpacityFunctionWidget_h

#include "pqPropertyWidget.h"
#include "pqSMProxy.h"

#include <QStringList>

class QComboBox;

class pqOpacityFunctionWidget : public pqPropertyWidget
{
  Q_OBJECT
  Q_PROPERTY(pqSMProxy function READ function WRITE setFunction NOTIFY functionChanged)
  using Superclass = pqPropertyWidget;

public:
  pqOpacityFunctionWidget(vtkSMProxy* proxy, vtkSMProperty* property, QWidget* parent = nullptr);
  ~pqOpacityFunctionWidget() override;

  /// The chosen opacity transfer function (null: none).
  pqSMProxy function() const;
  void setFunction(pqSMProxy function);

  /// The arrays the list offers, in its order.
  QStringList arrays();
  /// Takes the opacity transfer function of `array`, as choosing it in the list does.
  void chooseArray(const QString& array);

Q_SIGNALS:
  void functionChanged();

private:
  /// Fills the list again and selects the chosen function's array.
  void refresh();

  QComboBox* List;
  pqSMProxy Function;
};

#endif
