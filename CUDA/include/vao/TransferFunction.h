// The opacity transfer function of the Transfer Function method (docs/methods.md section
// 10): the nodes of a vtkPiecewiseFunction, without VTK, and its evaluation as VTK's
// vtkPiecewiseFunction::GetValue evaluates it, so that the openness follows the opacity the
// user sees in ParaView's Color Map Editor.
#pragma once

#include <vector>

namespace vao
{

/// One control point: the opacity y at value x; midpoint and sharpness shape the curve
/// from this point to the next (both in [0, 1]; 0.5 and 0 give a straight line).
struct OpacityNode
{
  double x = 0.0;
  double y = 0.0;
  double midpoint = 0.5;
  double sharpness = 0.0;
};

/// A piecewise opacity function: nodes in ascending x (equal x allowed, as ParaView's
/// opacity functions allow them), the value outside the nodes (clamping: the nearest end
/// node's opacity, else 0), and interpolation in log10(x) (logScale).
struct OpacityFunction
{
  std::vector<OpacityNode> nodes;
  bool clamping = true;
  bool logScale = false;
  // How the VTK in use evaluates the function, where its versions differ (the defaults
  // are VTK 9.2's; vtkAmbientOcclusionOpacity asks the VTK the filters run with).
  /// A value equal to a node's x: false, the end of the segment that reaches it (the first
  /// node at x; on the first node, outside the nodes), as VTK 9.2 evaluates it; true, the
  /// start of the segment that leaves it (the last node at x; on the last node, outside),
  /// as VTK 9.3 and later do.
  bool nodesStartSegments = false;
  /// Sharpness above 0.99: true, a step at the midpoint (VTK 9.2); false, the Hermite curve
  /// as for any other sharpness (VTK 9.3 and later).
  bool sharpSegmentsStep = true;
  /// The segment found by VTK 9.3's interpolation search, its quirks included, which VTK
  /// uses for (about ten thousand or more) nearly evenly spaced nodes; else by bisection.
  bool interpolationSearch = false;
};

/// alpha(x) as vtkPiecewiseFunction::GetValue(x) gives it: the first node at or beyond the
/// value and the one before it bound the segment (a value on the first node counts as
/// before the nodes, one on the last node as the end of the last segment; the other way
/// round with nodesStartSegments);
/// within the segment the position is moved by the midpoint, then sharpness below 0.01
/// interpolates linearly, above 0.99 steps at the midpoint and values between bend a
/// Hermite curve, clamped to the two nodes' opacities. NaN where the log scale meets a
/// value or node at or below 0. The function must pass checkOpacityFunction
/// (vao/Validation.h).
double evaluateOpacity(const OpacityFunction& function, double x);

} // namespace vao
