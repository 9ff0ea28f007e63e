/**
 * @class   vtkAmbientOcclusionDisplayDefaults
 * @brief   Shows each Ambient Occlusion filter's result when it is first shown in a view.
 *
 * ParaView shows a new image as an Outline coloured by its first array, and a new
 * surface coloured by its active scalars: an AO filter's result would stay hidden until
 * the user knows where to look. The XML's RepresentationType hints pick Slice or Volume;
 * this observer of the proxy manager does the rest when a filter's representation is
 * registered (Show() in pvpython and Apply in the GUI alike): it colours by the AO array
 * with a grey map over [0, 1] (a map made for this display only: an existing one may carry
 * the user's edits), and
 * shows Ambient Occlusion Shading's RGBA as colours, without a colour map.
 *
 * Representations loaded from a state file keep what the state says. The plugin installs
 * one observer when it is loaded (`Install`).
 */
#ifndef vtkAmbientOcclusionDisplayDefaults_h
#define vtkAmbientOcclusionDisplayDefaults_h

#include "vtkCommand.h"
#include "vtkWeakPointer.h"

#include <utility>
#include <vector>

class vtkSMProxy;

class vtkAmbientOcclusionDisplayDefaults : public vtkCommand
{
public:
  static vtkAmbientOcclusionDisplayDefaults* New();
  vtkBaseTypeMacro(vtkAmbientOcclusionDisplayDefaults, vtkCommand);

  /// Observe the proxy manager of this process, once, if it has one (this class and
  /// vtkAmbientOcclusionOpacityFitting).
  static void Install();

  void Execute(vtkObject* caller, unsigned long event, void* callData) override;

protected:
  vtkAmbientOcclusionDisplayDefaults() = default;
  ~vtkAmbientOcclusionDisplayDefaults() override = default;

private:
  /// Colours `representation` if it shows one of this plugin's filters.
  void Apply(vtkSMProxy* representation);
  /// Whether `lut` was registered after `time`.
  bool MadeSince(vtkSMProxy* lut, vtkMTimeType time) const;

  /// The colour maps registered so far, with when: a map made while a representation was
  /// set up is a default that Apply may replace.
  using NewMap = std::pair<vtkWeakPointer<vtkSMProxy>, vtkMTimeType>;
  std::vector<NewMap> NewMaps;

  vtkAmbientOcclusionDisplayDefaults(const vtkAmbientOcclusionDisplayDefaults&) = delete;
  void operator=(const vtkAmbientOcclusionDisplayDefaults&) = delete;
};

#endif
