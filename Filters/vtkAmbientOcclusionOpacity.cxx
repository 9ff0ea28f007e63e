#include "vtkAmbientOcclusionOpacity.h"

#include "vao/Validation.h"

#include "vtkNew.h"
#include "vtkPiecewiseFunction.h"
#include "vtkVersionMacros.h"

namespace vtkAmbientOcclusionOpacity
{
namespace
{

/// How the VTK this process runs with evaluates a function where its versions differ,
/// asked of VTK itself once (vao::OpacityFunction says what each flag means).
struct Evaluation
{
  bool nodesStartSegments = false;
  bool sharpSegmentsStep = true;
};

const Evaluation& VtkEvaluation()
{
  static const Evaluation evaluation = []
  {
    Evaluation e;
    // On the first node without clamping VTK 9.2 gives 0 (outside), 9.3 the node's opacity.
    vtkNew<vtkPiecewiseFunction> nodes;
    nodes->ClampingOff();
    nodes->AddPoint(0.0, 0.25);
    nodes->AddPoint(1.0, 0.75);
    e.nodesStartSegments = nodes->GetValue(0.0) != 0.0;
    // Sharpness 1 below the midpoint: VTK 9.2 steps (0), 9.3 follows the Hermite curve.
    vtkNew<vtkPiecewiseFunction> sharp;
    sharp->AddPoint(0.0, 0.0, 0.5, 1.0);
    sharp->AddPoint(1.0, 1.0);
    e.sharpSegmentsStep = sharp->GetValue(0.49) == 0.0;
    return e;
  }();
  return evaluation;
}

/// Whether VTK searches this function's nodes by interpolation (9.3 and later, for nearly
/// evenly spaced nodes) rather than by bisection.
bool InterpolationSearch(vtkPiecewiseFunction* function)
{
#if VTK_MAJOR_VERSION > 9 || (VTK_MAJOR_VERSION == 9 && VTK_MINOR_VERSION >= 3)
  return function->GetAutomaticSearchMethod() == vtkPiecewiseFunction::INTERPOLATION_SEARCH;
#else
  (void)function;
  return false;
#endif
}

} // namespace

vao::OpacityFunction Nodes(vtkPiecewiseFunction* function)
{
  vao::OpacityFunction nodes;
  nodes.nodesStartSegments = VtkEvaluation().nodesStartSegments;
  nodes.sharpSegmentsStep = VtkEvaluation().sharpSegmentsStep;
  if (!function)
  {
    return nodes;
  }
  nodes.interpolationSearch = InterpolationSearch(function);
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
