#include "vtkAmbientOcclusionOpacity.h"

#include "vao/Validation.h"

#include "vtkPiecewiseFunction.h"

namespace vtkAmbientOcclusionOpacity
{

vao::OpacityFunction Nodes(vtkPiecewiseFunction* function)
{
  vao::OpacityFunction nodes;
  if (!function)
  {
    return nodes;
  }
  nodes.clamping = function->GetClamping() != 0;
  nodes.logScale = function->GetUseLogScale();
  for (int i = 0; i < function->GetSize(); ++i)
  {
    double node[4]; // x, opacity, midpoint, sharpness
    function->GetNodeValue(i, node);
    nodes.nodes.push_back({ node[0], node[1], node[2], node[3] });
  }
  return nodes;
}

std::string Check(vtkPiecewiseFunction* function, const char* property)
{
  const vao::Status status = vao::checkOpacityFunction(Nodes(function));
  return status.ok ? std::string() : std::string(property) + ": " + status.message + ".";
}

} // namespace vtkAmbientOcclusionOpacity
