// The ray-cast ambient occlusion of a volume seen through its opacity transfer function
// (docs/methods.md section 11): what a ray tracer shows as the ambient occlusion of a
// semi-transparent volume. Exact Rays casts the rays; Rays estimates the same quantity
// from 26 cones around the lattice directions (docs/methods.md section 12).
#pragma once

#include <array>
#include <cstdint>

namespace vao
{

/// The world frame the rays run in and how they are cast (Exact Rays and Rays).
struct RayParameters
{
  /// R: how far a ray runs, in world units (> 0).
  double radius = 0.0;
  /// The voxel size along the image's x, y and z axes (world units, > 0).
  std::array<double, 3> spacing = { 1.0, 1.0, 1.0 };
  /// The image's direction matrix, row-major: index axis j points along its column j in
  /// world coordinates (orthonormal, as vtkImageData's).
  std::array<double, 9> direction = { 1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0 };
  /// u: the opacity alpha(v) is that of a segment of this length (world units); 0, the
  /// smallest spacing (a volume property's Scalar Opacity Unit Distance convention).
  double opacityUnitDistance = 0.0;
  /// n: the rays per voxel, along the Fibonacci sphere of n points (Exact Rays only).
  int rayCount = 128;
};

/// The largest accepted RayCount: beyond it the rays no longer change the result.
constexpr int kMaximumRayCount = 65536;

/// The half-widths in voxels of what a voxel's ray-cast AO reads, per axis: ceil(R / h_a),
/// the interpolation's second voxel included. A piece grown by this reach, clipped to the
/// whole extent, gives its voxels the serial result.
std::array<int, 3> rayReach(const RayParameters& rays);

/// The same for Rays: its cones' lattice points and the blur they read (a little more than
/// rayReach).
std::array<int, 3> rayEstimateReach(const RayParameters& rays);

} // namespace vao
