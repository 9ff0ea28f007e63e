/**
 * @class   vtkAmbientOcclusionOpacityFitting
 * @brief   Fits an untouched opacity function to the data before a filter uses it.
 *
 * ParaView makes an array's opacity transfer function with two points at 0 and 1 and
 * fits it to the data's range only when something is coloured by that array. A filter
 * given such a function (Volumetric AO's Transfer Function method, Ambient Occlusion
 * Shading's OpacityTransferFunction) would read a step between 0 and 1, in the data's
 * units (HU on a CT), and its result would change silently once the array is coloured.
 * This observer of the proxy manager fits such a function to the range of the filter's
 * Scalars, as colouring would, when the filter is registered or its function, method or
 * array changes: in the GUI and in pvpython alike. A function whose points or range were
 * set is left as it is.
 */
#ifndef vtkAmbientOcclusionOpacityFitting_h
#define vtkAmbientOcclusionOpacityFitting_h

#include "vtkCommand.h"

class vtkSMProxy;

class vtkAmbientOcclusionOpacityFitting : public vtkCommand
{
public:
  static vtkAmbientOcclusionOpacityFitting* New();
  vtkBaseTypeMacro(vtkAmbientOcclusionOpacityFitting, vtkCommand);

  void Execute(vtkObject* caller, unsigned long event, void* callData) override;

  /// Fits the opacity function `filter` uses, if it is untouched, to its Scalars' range.
  static void Fit(vtkSMProxy* filter);

protected:
  vtkAmbientOcclusionOpacityFitting() = default;
  ~vtkAmbientOcclusionOpacityFitting() override = default;

private:
  vtkAmbientOcclusionOpacityFitting(const vtkAmbientOcclusionOpacityFitting&) = delete;
  void operator=(const vtkAmbientOcclusionOpacityFitting&) = delete;
};

#endif
