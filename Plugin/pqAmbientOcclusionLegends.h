/**
 * @class   pqAmbientOcclusionLegends
 * @brief   No colour legend for a result whose colours are not mapped (the GUI only).
 *
 * Ambient Occlusion Shading's RGBA are shown as they are (Map Scalars off,
 * vtkAmbientOcclusionDisplayDefaults): a colour legend would describe a map the view does
 * not use. ParaView's Apply shows a legend for every newly coloured representation; after
 * each Apply this hides the legends of such representations.
 */
#ifndef pqAmbientOcclusionLegends_h
#define pqAmbientOcclusionLegends_h

#include <QObject>

class pqAmbientOcclusionLegends : public QObject
{
  Q_OBJECT

public:
  pqAmbientOcclusionLegends(QObject* parent = nullptr);
  ~pqAmbientOcclusionLegends() override = default;

  /// The plugin's auto-start: follows the Properties panel's Apply.
  void startup();
  void shutdown() {}

private Q_SLOTS:
  void followApply();
  void hideUnmappedLegends();

private:
  int Tries = 0;
};

#endif
