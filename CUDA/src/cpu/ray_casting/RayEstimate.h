// Rays on the CPU (RayEstimate.cxx): an estimate of Exact Rays' AO from 26 lattice cones
// (docs/methods.md section 12), whose cost grows like the logarithm of the radius.
#pragma once

#include "vao/AmbientOcclusion.h"

#include <array>
#include <vector>

namespace vao
{
namespace detail
{

/// One sample of a cone's near part: the extinction of the value interpolated at
/// `fraction` of the lattice step, over `length` world units.
struct NearSample
{
  double fraction = 0.0;
  double length = 0.0;
};

/// One sample of a cone's far part: blur level `level` (0: the cell means themselves) at
/// `step` lattice steps, over `length` world units.
struct FarSample
{
  int step = 0;
  int level = 0;
  double length = 0.0;
};

/// A cone around a lattice direction: its index step, its share of the sphere, its samples.
struct LatticeCone
{
  std::array<int, 3> step{};
  double weight = 0.0;
  std::vector<NearSample> near;
  std::vector<FarSample> far;
};

/// Everything Rays computes from the parameters alone, before it reads a voxel.
struct RayPlan
{
  std::vector<LatticeCone> cones;
  /// Blur level l > 0 is a box mean of side levelSides[l] world units (level 0: none).
  std::vector<double> levelSides;
  /// The voxels a result reads along each axis (the halo of a piece).
  std::array<int, 3> reach{};
  double unit = 1.0; // the opacity unit distance, world units
};

/// The plan of the rays' parameters (checkRayParameters passed).
RayPlan planRays(const RayParameters& rays);

/// Rays' AO of every region voxel (docs/methods.md section 12); their range into `range`
/// unless it is null. The parameters must pass checkOpacityFunction and checkRayParameters.
Status computeRays(const VolumeView& volume, const Region& region,
  const AmbientOcclusionParameters& parameters, float* openness, OutputRange* range,
  const Execution& execution);

} // namespace detail
} // namespace vao
