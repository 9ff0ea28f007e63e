// Private helper of the module's filters: the frame of an oriented image. VTK places
// index (i, j, k) of an image at origin + D (spacing * index), D its direction matrix; the
// kernels work in the image's own axis-aligned frame, origin + spacing * index. Surfaces,
// normals and lights given in the physical frame are turned into the image's before a
// kernel sees them, and images the kernels lay out (pyramid levels) are placed back in
// the physical frame. D must be orthonormal (a rotation, with or without a reflection):
// then lengths and angles, and with them distances, radii and AO, are the same in both
// frames. Not part of the module's public interface.
#ifndef vtkAmbientOcclusionFrame_h
#define vtkAmbientOcclusionFrame_h

#include <array>
#include <string>

class vtkImageData;
class vtkPolyData;

namespace vao
{
struct VolumeView;
}

namespace vtkAmbientOcclusionFrame
{

struct Frame
{
  std::array<double, 3> origin = { 0.0, 0.0, 0.0 };
  std::array<double, 9> direction = { 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0 }; // row-major D
  bool identity = true; // D is the identity: both frames are one

  /// A physical point in the image's frame: origin + D^T (p - origin).
  std::array<double, 3> PointToImage(const double p[3]) const;
  /// A physical direction (normal, light) in the image's frame: D^T v.
  std::array<double, 3> VectorToImage(const double v[3]) const;
  /// A point of the image's frame in the physical one: origin + D (p - origin).
  std::array<double, 3> PointToWorld(const double p[3]) const;
};

/// The frame of `image`. False, with the reason in `error`, when its direction matrix is
/// not orthonormal (to 1e-5: directions read from files are rounded) or not finite.
bool FrameOf(vtkImageData* image, Frame& frame, std::string& error);

/// Places `part`, laid out in the frame's image coordinates (its origin there), in the
/// physical frame: its origin mapped, the frame's direction matrix copied.
void PlaceInWorld(const Frame& frame, vtkImageData* part);

/// Whether the points of `surface` (some of them) lie on the iso-surface of the oriented
/// volume (`volume` in `frame`, its grid at `origin` and `spacing` in the image's frame)
/// only along the image's axes, its direction matrix ignored: what VTK 9.2's
/// vtkContourFilter and ParaView 5.11's Contour extract from an oriented image.
bool SurfaceAlongImageAxes(vtkPolyData* surface, const vao::VolumeView& volume, const Frame& frame,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing);

/// The bounds of the surface's points in the image's axis-aligned frame (from `frame`).
void SurfaceBoundsInFrame(vtkPolyData* surface, const Frame& frame, double bounds[6]);

/// Whether the points of `surface` lie in the extent `ext` of `grid`'s voxels grown by
/// `slack` voxels (clipped to `whole`), half a voxel of rounding allowed: a Contour of a
/// piece, whose ghost cells reach past it. Axis-aligned grids only (false otherwise).
bool SurfaceWithinExtent(
  vtkPolyData* surface, vtkImageData* grid, const int ext[6], const int whole[6], int slack);

} // namespace vtkAmbientOcclusionFrame

#endif
