#include "vtkAmbientOcclusionFrame.h"

#include "vtkImageData.h"
#include "vtkMatrix3x3.h"

#include <algorithm>
#include <cmath>
#include <sstream>

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

} // namespace vtkAmbientOcclusionFrame
