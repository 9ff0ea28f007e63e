#include "vtkAmbientOcclusionOpacity.h"

#include "vao/Validation.h"

#include "vtkNew.h"
#include "vtkPiecewiseFunction.h"

namespace vtkAmbientOcclusionOpacity
{
namespace
{

bool NodesStartSegments()
{
  // VTK 9.3 changed which segment a value on a node belongs to; this process follows the
  // VTK it runs with. Off the nodes the versions agree; on the first node without clamping
  // 9.2 gives 0 (outside) and 9.3 the node's opacity.
  static const bool starts = []
  {
    vtkNew<vtkPiecewiseFunction> probe;
    probe->ClampingOff();
    probe->AddPoint(0.0, 0.25);
    probe->AddPoint(1.0, 0.75);
    return probe->GetValue(0.0) != 0.0;
  }();
  return starts;
}

} // namespace

vao::OpacityFunction Nodes(vtkPiecewiseFunction* function)
{
  vao::OpacityFunction nodes;
  nodes.nodesStartSegments = NodesStartSegments();
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
