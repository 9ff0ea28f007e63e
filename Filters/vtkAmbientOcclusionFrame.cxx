#include "vtkAmbientOcclusionFrame.h"

#include "vtkAmbientOcclusionExtents.h"

#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkPolyData.h"

#include "vao/VarianceOcclusionMap.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

namespace vtkAmbientOcclusionFrame
{

std::array<double, 3> Frame::PointToImage(const double p[3]) const
{
  const double d[3] = { p[0] - this->origin[0], p[1] - this->origin[1], p[2] - this->origin[2] };
  const std::array<double, 3> r = this->VectorToImage(d);
  return { this->origin[0] + r[0], this->origin[1] + r[1], this->origin[2] + r[2] };
}

std::array<double, 3> Frame::VectorToImage(const double v[3]) const
{
  const std::array<double, 9>& m = this->direction;
  return { m[0] * v[0] + m[3] * v[1] + m[6] * v[2], m[1] * v[0] + m[4] * v[1] + m[7] * v[2],
    m[2] * v[0] + m[5] * v[1] + m[8] * v[2] };
}

std::array<double, 3> Frame::PointToWorld(const double p[3]) const
{
  const std::array<double, 9>& m = this->direction;
  const double d[3] = { p[0] - this->origin[0], p[1] - this->origin[1], p[2] - this->origin[2] };
  std::array<double, 3> r;
  for (int i = 0; i < 3; ++i)
    r[i] = this->origin[i] + m[3 * i] * d[0] + m[3 * i + 1] * d[1] + m[3 * i + 2] * d[2];
  return r;
}

bool FrameOf(vtkImageData* image, Frame& frame, std::string& error)
{
  const double* o = image->GetOrigin();
  frame.origin = { o[0], o[1], o[2] };
  const double* m = image->GetDirectionMatrix()->GetData();
  std::copy(m, m + 9, frame.direction.begin());
  frame.identity = true;
  double worst = 0.0; // of D^T D - I
  for (int i = 0; i < 3; ++i)
    for (int j = 0; j < 3; ++j)
    {
      frame.identity = frame.identity && m[3 * i + j] == (i == j ? 1.0 : 0.0);
      const double dot = m[i] * m[j] + m[3 + i] * m[3 + j] + m[6 + i] * m[6 + j];
      const double off = std::abs(dot - (i == j ? 1.0 : 0.0));
      worst = std::isfinite(off) ? std::max(worst, off) : INFINITY;
    }
  if (!(worst <= 1e-5))
  {
    std::ostringstream why;
    why << "The image's direction matrix (" << m[0] << " " << m[1] << " " << m[2] << ", " << m[3]
        << " " << m[4] << " " << m[5] << ", " << m[6] << " " << m[7] << " " << m[8]
        << ") is not a rotation: its columns must be orthogonal unit vectors (resample the image "
           "onto such a grid "
           "first).";
    error = why.str();
    return false;
  }
  return true;
}

void PlaceInWorld(const Frame& frame, vtkImageData* part)
{
  if (frame.identity)
    return;
  const std::array<double, 3> origin = frame.PointToWorld(part->GetOrigin());
  part->SetOrigin(origin.data());
  part->SetDirectionMatrix(frame.direction.data());
}

namespace
{
// The frame a surface is in (SurfaceAlongImageAxes): the workaround for VTK 9.2's
// vtkContourFilter and vtkSynchronizedTemplates3D (ParaView 5.11's Contour), which ignore an
// oriented image's direction matrix. VTK places an oriented image's voxels at origin + D
// (spacing index); vtkFlyingEdges3D and vtkMarchingCubes put a contour there, while those
// two leave it along the image's axes. A contour's points lie on grid edges, where the
// trilinear volume takes the iso value: the frame in which the sampled values agree is the
// surface's. The axes win only where the physical frame's values clearly disagree: the
// points of a physical surface read along the axes may all fall in flat air, and agree
// there too.
/// The points read: every (n / kFrameSamples)-th of n, so all of a surface under 1024
/// points and 512 to 768 of a larger one; enough for the medians, few beside the shading.
constexpr vtkIdType kFrameSamples = 512;
/// The physical frame's values disagree: their median deviation exceeds this fraction of
/// the spread of every value read (both frames').
constexpr double kFrameDisagreement = 1e-4;
/// The axes' values agree: their median deviation is below this fraction of the
/// physical frame's.
constexpr double kAxesAgreement = 1e-3;

/// The median distance of the values from their median: near 0 when nearly all agree.
double MedianDeviation(std::vector<double> values)
{
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  const double median = *middle;
  for (double& v : values)
    v = std::abs(v - median);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

} // namespace

bool SurfaceAlongImageAxes(vtkPolyData* surface, const vao::VolumeView& volume, const Frame& frame,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing)
{
  const vtkIdType n = surface->GetNumberOfPoints();
  std::vector<double> inFrame, alongAxes;
  for (vtkIdType i = 0; i < n; i += std::max<vtkIdType>(1, n / kFrameSamples))
  {
    const double* p = surface->GetPoint(i);
    inFrame.push_back(vao::sampleVolume(volume, origin, spacing, frame.PointToImage(p)));
    alongAxes.push_back(vao::sampleVolume(volume, origin, spacing, { p[0], p[1], p[2] }));
  }
  const auto [low, high] = std::minmax_element(inFrame.begin(), inFrame.end());
  const auto [lowAxes, highAxes] = std::minmax_element(alongAxes.begin(), alongAxes.end());
  const double spread = std::max(*high, *highAxes) - std::min(*low, *lowAxes);
  const double disagreement = MedianDeviation(inFrame);
  return disagreement > kFrameDisagreement * spread &&
    MedianDeviation(alongAxes) < kAxesAgreement * disagreement;
}

void SurfaceBoundsInFrame(vtkPolyData* surface, const Frame& frame, double bounds[6])
{
  if (frame.identity)
  {
    surface->GetBounds(bounds);
    return;
  }
  for (int a = 0; a < 3; ++a)
  {
    bounds[2 * a] = std::numeric_limits<double>::infinity();
    bounds[2 * a + 1] = -bounds[2 * a];
  }
  const vtkIdType n = surface->GetNumberOfPoints();
  for (vtkIdType i = 0; i < n; ++i)
  {
    const std::array<double, 3> p = frame.PointToImage(surface->GetPoint(i));
    for (int a = 0; a < 3; ++a)
    {
      bounds[2 * a] = std::min(bounds[2 * a], p[a]);
      bounds[2 * a + 1] = std::max(bounds[2 * a + 1], p[a]);
    }
  }
}

bool SurfaceWithinExtent(
  vtkPolyData* surface, vtkImageData* grid, const int ext[6], const int whole[6], int slack)
{
  if (vtkAmbientOcclusionExtents::EmptyExtent(ext) || !grid->GetDirectionMatrix()->IsIdentity())
    return false;
  const int slacks[3] = { slack, slack, slack };
  int reached[6];
  std::copy(ext, ext + 6, reached);
  vtkAmbientOcclusionExtents::GrowExtent(reached, slacks, whole);
  const double* bounds = surface->GetBounds();
  const double* origin = grid->GetOrigin();
  const double* h = grid->GetSpacing();
  for (int a = 0; a < 3; ++a)
    if (bounds[2 * a] < origin[a] + (reached[2 * a] - 0.5) * h[a] ||
      bounds[2 * a + 1] > origin[a] + (reached[2 * a + 1] + 0.5) * h[a])
      return false;
  return true;
}

} // namespace vtkAmbientOcclusionFrame
