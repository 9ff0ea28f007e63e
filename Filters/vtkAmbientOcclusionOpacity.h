// Private helper of the module's filters: an opacity transfer function (vtkPiecewiseFunction)
// as the kernel's nodes (vao/TransferFunction.h), and its one check, for every filter that
// takes one (Volumetric AO's Transfer Function method, Ambient Occlusion Shading).
#ifndef vtkAmbientOcclusionOpacity_h
#define vtkAmbientOcclusionOpacity_h

#include "vao/TransferFunction.h"

#include <string>

class vtkPiecewiseFunction;

namespace vtkAmbientOcclusionOpacity
{

/// The function's points, clamping and log scale (empty nodes for null), and which segment
/// a value on a node belongs to in the VTK this process runs with (VTK 9.2 and 9.3 differ).
vao::OpacityFunction Nodes(vtkPiecewiseFunction* function);

/// "" when the function is fit to use (vao::checkOpacityFunction), else the sentence for
/// the error, naming the filter's property.
std::string Check(vtkPiecewiseFunction* function, const char* property);

} // namespace vtkAmbientOcclusionOpacity

#endif
