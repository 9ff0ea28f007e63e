// Occlusion sweeping (Singh, Yuksel & House 2009), host code: the signed distance field
// of an isosurface by fast sweeping, with the visibility of the eight octants of the sky
// propagated in the same sweeps. Definitions: docs/methods.md, Singh et al.
#pragma once

#include "vao/AmbientOcclusion.h"

#include <array>
#include <cstdint>

namespace vao
{

struct SweepParameters
{
  double isoValue = 0.0;
  bool insideIsAbove = true; // inside (occluding) = v > c; false: v < c
  int iterations = 1;        // passes of the 8 sweeps (the paper: 1)
  // > 0: stop early after a pass that changes no finite |D| by as much (world units) and
  // reaches no voxel for the first time (so the first pass never counts as converged).
  double tolerance = 0.0;
  // Octants that light ambientOcclusion (Table 1 order); at least one when it is requested.
  std::array<bool, 8> octantMask = { true, true, true, true, true, true, true, true };
  // A = sum_s m_s V_s / sum_s m_s without it; with it A = (1/pi) sum_s m_s V_s G_s(N),
  // N = the normalised gradient of D (two-sided and over 2 pi when opacity < 1).
  bool useGeometryTerm = false;
  double gamma = 1.0;   // A <- A^(1 / gamma)
  double opacity = 1.0; // translucency alpha in [0, 1]; 1 = opaque
};

/// Output arrays of volume.voxelCount() values (x fastest); null skips one.
struct SweepOutput
{
  float* signedDistance = nullptr;   // > 0 outside, < 0 inside, world units
  float* ambientOcclusion = nullptr; // in [0, 1]
  float* octantVisibility = nullptr; // 8 values per voxel, Table 1 order
};

struct SweepReport
{
  int passes = 0;          // passes of 8 sweeps run
  double lastChange = 0.0; // largest change of a finite |D| in the last pass (world units)
  // false: no grid edge crosses the iso value; then D = +-(the volume's diagonal) and every
  // octant is open (V = 1, all outside) or closed (V = 0, all inside), and passes = 0.
  bool surfaceFound = true;
};

/// The whole volume (sweeping is global). Spacing in world units per axis. Rejects
/// (Status::failure, with the reason) volumes under 2 voxels on an axis, non-finite values
/// and out-of-range parameters; returns Status::cancelled() when execution asks to abort.
Status computeOcclusionSweeping(const VolumeView& volume, const std::array<double, 3>& spacing,
  const SweepParameters& parameters, const SweepOutput& output, const Execution& execution = {},
  SweepReport* report = nullptr);

/// Sweep s (0..7, Table 1 order) as its direction signs: s = 0 is (+1, +1, +1), the x sign
/// flips fastest (s = 1 is (-1, +1, +1)), then y, then z.
std::array<int, 3> sweepDirection(int octant);

/// G_s(N) = integral over octant s of max(N.w, 0) dw (Eq. 5), in closed form. N is
/// normalised first; a zero or non-finite N counts as +z (as for a flat distance field).
/// Sweep s moves along sweepDirection(s) and reads its upwind neighbours P - h*dir, so it
/// carries the light that arrives from the directions w (pointing from P to the sky)
/// with sign(w) = -sweepDirection(s): octant s is that set. A floor below P blocks the
/// sweeps moving up (dir z = +1, s = 0..3); the upper four octants (the paper's cloudy
/// day) are s = 4..7. sum_s G_s(N) = pi. twoSided: the integral of |N.w| (sum 2 pi).
/// An octant outside 0..7 gives 0.
double geometryTerm(int octant, const std::array<double, 3>& normal, bool twoSided = false);

} // namespace vao
