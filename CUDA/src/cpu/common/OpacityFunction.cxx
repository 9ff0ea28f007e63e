// evaluateOpacity (vao/TransferFunction.h): VTK's piecewise-function evaluation written
// without VTK, 9.2's or 9.3's convention on the nodes themselves. The tests compare it with
// vtkPiecewiseFunction::GetValue itself.
#include "vao/TransferFunction.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>

namespace vao
{

namespace
{

/// VTK keeps the midpoint this far from 0 and 1, where its rescaling would divide by 0.
constexpr double kMidpointMargin = 1e-5;

/// The position in [0, 1] within the segment [x1, x2], in log10 where the function asks.
double segmentPosition(const OpacityFunction& f, double x, double x1, double x2)
{
  if (f.logScale)
  {
    const double l1 = std::log10(x1);
    return (std::log10(x) - l1) / (std::log10(x2) - l1);
  }
  return (x - x1) / (x2 - x1);
}

/// The opacity between two nodes at `scale`, VTK's curve: the midpoint moves the position,
/// then a step at the moved midpoint (sharpness above 0.99, where `sharpStep`), a straight
/// line (below 0.01) or the Hermite curve sharpened by raising the position to the power
/// 1 + 10 sharpness, clamped to the two nodes' opacities.
double segmentOpacity(const OpacityNode& a, const OpacityNode& b, double scale, bool sharpStep)
{
  const double midpoint = std::min(std::max(a.midpoint, kMidpointMargin), 1.0 - kMidpointMargin);
  scale =
    scale < midpoint ? 0.5 * scale / midpoint : 0.5 + 0.5 * (scale - midpoint) / (1.0 - midpoint);
  const double sharpness = a.sharpness;
  if (sharpness > 0.99 && sharpStep)
  {
    return scale < 0.5 ? a.y : b.y;
  }
  if (sharpness < 0.01)
  {
    return (1 - scale) * a.y + scale * b.y;
  }
  const double power = 1.0 + 10 * sharpness;
  if (scale < 0.5)
  {
    scale = 0.5 * std::pow(scale * 2, power);
  }
  else if (scale > 0.5)
  {
    scale = 1.0 - 0.5 * std::pow((1.0 - scale) * 2, power);
  }
  const double ss = scale * scale;
  const double sss = ss * scale;
  const double h1 = 2 * sss - 3 * ss + 1;
  const double h2 = -2 * sss + 3 * ss;
  const double h3 = sss - 2 * ss + scale;
  const double h4 = sss - ss;
  const double tangent = (1.0 - sharpness) * (b.y - a.y);
  const double value = h1 * a.y + h2 * b.y + h3 * tangent + h4 * tangent;
  const double lowest = std::min(a.y, b.y);
  const double highest = std::max(a.y, b.y);
  return std::min(std::max(value, lowest), highest);
}

/// The index of the segment's upper node as VTK 9.3's interpolation search finds it (the
/// node count beyond the nodes, 0 before them). Where VTK would divide 0 by 0 (a value on
/// repeated last nodes) this takes the current node.
std::size_t interpolationSearch(const std::vector<OpacityNode>& nodes, double x)
{
  const std::size_t n = nodes.size(), last = n - 1;
  if (x > nodes[last].x)
  {
    return n;
  }
  std::size_t begin = 0, mid = 0;
  bool movedRight = false;
  while (begin != n && nodes[begin].x <= x && x <= nodes[last].x)
  {
    const double span = nodes[last].x - nodes[begin].x;
    const double fraction = span > 0.0 ? (x - nodes[begin].x) / span : 0.0;
    mid = begin + static_cast<std::size_t>(fraction * (static_cast<double>(n - begin) - 1.0));
    if (!(nodes[mid].x < x))
    {
      return mid;
    }
    begin = mid + 1;
    movedRight = true;
  }
  return movedRight ? mid + 1 : mid;
}

/// The index of the segment's upper node: VTK 9.2's first node at or beyond x, or 9.3's
/// first node beyond it (or its interpolation search).
std::size_t upperNode(const OpacityFunction& f, double x)
{
  const std::vector<OpacityNode>& nodes = f.nodes;
  if (f.interpolationSearch)
  {
    return interpolationSearch(nodes, x);
  }
  const auto upper = f.nodesStartSegments
    ? std::upper_bound(nodes.begin(), nodes.end(), x,
        [](double value, const OpacityNode& node) { return value < node.x; })
    : std::lower_bound(nodes.begin(), nodes.end(), x,
        [](const OpacityNode& node, double value) { return node.x < value; });
  return static_cast<std::size_t>(upper - nodes.begin());
}

} // namespace

double evaluateOpacity(const OpacityFunction& f, double x)
{
  const std::vector<OpacityNode>& nodes = f.nodes;
  if (nodes.empty())
  {
    return 0.0;
  }
  // The segment is the first node at or beyond x and the one before it: a value on the
  // first node counts as before the nodes (0 without clamping), one on the last as its end.
  // Where nodes start segments, the first node beyond x and the one before it: a value on
  // the first node starts the first segment, one on the last is beyond the nodes.
  const std::size_t upper = upperNode(f, x);
  if (upper >= nodes.size())
  {
    return f.clamping ? nodes.back().y : 0.0;
  }
  if (upper == 0)
  {
    return f.clamping ? nodes.front().y : 0.0;
  }
  const OpacityNode& a = nodes[upper - 1];
  const OpacityNode& b = nodes[upper];
  const double scale = segmentPosition(f, x, a.x, b.x);
  if (std::isnan(scale))
  {
    return std::numeric_limits<double>::quiet_NaN();
  }
  return segmentOpacity(a, b, scale, f.sharpSegmentsStep);
}

} // namespace vao
