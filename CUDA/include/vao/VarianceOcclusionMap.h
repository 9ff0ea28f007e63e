// Variance occlusion maps (Penner & Mitchell 2008), host code: a pyramid of Gaussian-
// blurred moments of the volume, sampled at points offset from an isosurface to estimate
// its ambient occlusion and soft shadows. Definitions: docs/methods.md, Penner and
// Mitchell. The pyramid is built once; moving the iso value, the surface or the light
// only samples it again.
#pragma once

#include "vao/AmbientOcclusion.h"
#include "vao/Storage.h"

#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <new>
#include <utility>
#include <vector>

namespace vao
{

/// The value of a bound that is not set (MomentLevel::wholeBounds).
constexpr double kUnsetBound = std::numeric_limits<double>::quiet_NaN();

/// A level's floats, in storage (vao/Storage.h): filled by the pyramid builder's threads.
using LevelArray = StorageArray<float>;

/// One level of the pyramid: blurred first moment (the mean) and variance, x fastest.
struct MomentLevel
{
  Index3 dims = { 0, 0, 0 };
  std::array<double, 3> origin = { 0, 0, 0 };  // world position of voxel (0, 0, 0)
  std::array<double, 3> spacing = { 1, 1, 1 }; // world units
  double kernelRadius = 0.0;                   // r_l = 2 * largest spacing of this level (world)
  // World bounds (x0, x1, y0, y1, z0, z1) of the whole volume's level when this level holds
  // only a window of it (a distributed piece); NaN: the level is whole. The soft-shadow
  // march of pyramid[0] stops at these bounds, not at the window's.
  std::array<double, 6> wholeBounds = { kUnsetBound, kUnsetBound, kUnsetBound, kUnsetBound,
    kUnsetBound, kUnsetBound };
  LevelArray mean;
  LevelArray variance; // E[v^2] - E[v]^2 of the blurred moments, clamped at 0
  // The range of each, kept as buildMomentPyramid writes the level (a caller handing the
  // arrays on need not read them again); not known for a level built otherwise.
  OutputRange meanRange, varianceRange;
  // The variance rounding alone can leave in a flat region (sumRoundingVariance of the
  // volume's largest deviation from the moments' shift): the estimators treat a sample
  // at or below it as flat.
  double roundingVariance = 0.0;
};

struct PyramidParameters
{
  int levels = 4;
  bool startAtHalfResolution = false;
};

/// Level 0 blurs the volume with a separable normalised 5-tap Gaussian per axis (sigma = 1
/// voxel; weights renormalised where the kernel leaves the volume, so a constant stays
/// constant) at full resolution, or with startAtHalfResolution keeps every second voxel
/// of that blur. Each next level blurs the previous one the same way and keeps voxels 0, 2,
/// 4, ... per axis: dims (n + 1) / 2, spacing doubled, origin unchanged (the effective
/// kernel doubles). Moments are taken about the volume's sampled mean and accumulated in
/// double; levels store mean and variance as float. The volume must be 3-D (>= 2 voxels
/// per axis) and finite, the spacing finite and positive, 1 <= levels <= 16; on failure
/// the pyramid is left empty. A pyramid passed in from an earlier build of the same size
/// is rebuilt in its own storage (no reallocation).
Status buildMomentPyramid(const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const PyramidParameters& parameters,
  std::vector<MomentLevel>& pyramid, const Execution& execution = {});

/// How coarsely a level's float32 means resolve its values: half a float ulp of its largest
/// |mean| over the spread (largest minus smallest) of its means; 0 for a constant level.
/// Values far from 0 against their spread lose detail: the CT head at an offset of 1e6
/// gives 4e-5 on its coarsest level (AO and Shadow within 1e-3 of the scan's), at 1e7 4e-4
/// (within 7e-3). Past kCoarseMeanResolution the filters warn.
double meanResolution(const MomentLevel& level);
constexpr double kCoarseMeanResolution = 1e-4;

enum class SurfaceQuery : int
{
  HalfVoxelInside = 0, // q = v(p - h/2 n), the paper's default
  IsoValue = 1,        // q = c
};

enum class LevelCombination : int
{
  MaximumOcclusion = 0,
  Mean = 1,
};

struct SurfaceOcclusionParameters
{
  SurfaceQuery query = SurfaceQuery::HalfVoxelInside;
  double isoValue = 0.0;
  double offsetFactor = 1.0;            // k: samples at p + k r_l n
  Method estimator = Method::Chebyshev; // Chebyshev or GaussianCdf (the only ones a level's
                                        // blurred mean and variance can feed)
  LevelCombination combination = LevelCombination::MaximumOcclusion;
  int levels = -1; // levels used, -1: all of the pyramid
};

/// Ambient occlusion (1 = open) of surface points p with outward normals n (towards lower
/// values; normalised here, must be finite and non-zero). Query q = the iso value, or (the
/// default) v(p - h/2 n): the volume trilinearly interpolated half a voxel inside, with
/// `origin`/`spacing` the volume's geometry and h its smallest spacing (the volume is
/// only read for that query). Level l (l < parameters.levels, -1: all) samples mean and
/// variance at p + k r_l n; its occlusion is 1 - the Chebyshev (or Gaussian CDF, exact
/// erf) openness of q; levels combine by maximum (default) or mean; out = 1 - occlusion.
/// Points: 3 doubles each; normals: 3 doubles each; out: one float per point.
Status surfaceAmbientOcclusion(const std::vector<MomentLevel>& pyramid, const VolumeView& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing, const double* points,
  const double* normals, std::int64_t count, const SurfaceOcclusionParameters& parameters,
  float* out, const Execution& execution = {});

/// The same with float points and normals (vtkPoints' usual type), read in place.
Status surfaceAmbientOcclusion(const std::vector<MomentLevel>& pyramid, const VolumeView& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing, const float* points,
  const float* normals, std::int64_t count, const SurfaceOcclusionParameters& parameters,
  float* out, const Execution& execution = {});

/// Soft shadow (1 = lit) of surface points towards the light direction L (need not be
/// unit; must be finite and not zero): a march along L starting at p + r_0 n (off the
/// surface); at distance t it samples level l = clamp(floor(log2(1 + t / r_0)), 0,
/// levels - 1) and steps r_l / 2; occlusion = the maximum over the steps of 1 - the
/// openness of q (the estimator of `parameters`); it stops on leaving level 0's bounds or
/// at occlusion >= 0.999. There is no raw volume here, so the half-voxel-inside query reads
/// level 0's (blurred) mean at p - h/2 n (h: level 0's smallest spacing); IsoValue gives
/// q = c exactly. offsetFactor and combination are not used.
Status surfaceShadow(const std::vector<MomentLevel>& pyramid, const double* points,
  const double* normals, std::int64_t count, const std::array<double, 3>& lightDirection,
  const SurfaceOcclusionParameters& parameters, float* out, const Execution& execution = {});

/// The same with float points and normals, read in place.
Status surfaceShadow(const std::vector<MomentLevel>& pyramid, const float* points,
  const float* normals, std::int64_t count, const std::array<double, 3>& lightDirection,
  const SurfaceOcclusionParameters& parameters, float* out, const Execution& execution = {});

class PyramidTiles; // levels 0 and 1 of a SurfacePyramid, in tiles (the kernel's own)

/// A moment pyramid for the surface queries that holds levels 0 and 1 only where they
/// sample them. Those levels (96% of a whole pyramid's bytes) are kept in tiles of 8^3
/// cells (9^3 voxels, the ninth shared with the next tile): a query builds the tiles its
/// samples reach (its points' AO offsets, the half-voxel query, the shadow march's steps
/// on those levels), so a surface holds a small part of them. It sweeps its points in
/// slabs along z, building a slab's tiles before sampling it, and gives back the tiles it
/// has left behind while more than keptTileBytes() are built (by default a fifth of the
/// volume's bytes, at least 16 MiB): a large surface holds the tiles near one slab plus
/// those kept, which the next query finds built.
/// Levels 2 and up are whole. Every result equals the one from
/// buildMomentPyramid's whole pyramid bit for bit. Tiles are built from the volume: the
/// volume the pyramid was built from must outlive it, unchanged. A query builds tiles, so
/// queries on one pyramid must not run at the same time (each runs on all the threads of
/// its Execution already).
class SurfacePyramid
{
public:
  SurfacePyramid();
  ~SurfacePyramid();
  SurfacePyramid(SurfacePyramid&& other) noexcept;
  SurfacePyramid& operator=(SurfacePyramid&& other) noexcept;

  /// The levels; the tiled ones (0 and 1) have their geometry and no arrays.
  const std::vector<MomentLevel>& levels() const { return this->Levels; }
  bool empty() const { return this->Levels.empty(); }
  void clear();
  /// Level l's tiles built so far, and in all (0 for a whole level).
  std::int64_t builtTiles(int level) const;
  std::int64_t tileCount(int level) const;
  /// The memory of the tiles: the most held at once (released tiles leave their room to
  /// the next ones built).
  std::size_t tileMemory() const;
  /// The tiles' bytes a query keeps built (past them it releases the ones it left behind).
  std::size_t keptTileBytes() const;
  void setKeptTileBytes(std::size_t bytes);

private:
  friend struct SurfacePyramidAccess; // the builder's and the queries' way in
  std::vector<MomentLevel> Levels;
  std::unique_ptr<PyramidTiles> Tiles;
};

/// The pyramid of buildMomentPyramid (same checks, levels 2 and up the same), levels 0
/// and 1 left to be built in tiles by the queries. On failure the pyramid is left empty.
Status buildSurfacePyramid(const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const PyramidParameters& parameters,
  SurfacePyramid& pyramid, const Execution& execution = {});

/// surfaceAmbientOcclusion and surfaceShadow on a SurfacePyramid: the tiles the points
/// reach are built as the query sweeps them (kept for later queries up to the pyramid's
/// keptTileBytes()).
Status surfaceAmbientOcclusion(SurfacePyramid& pyramid, const VolumeView& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing, const double* points,
  const double* normals, std::int64_t count, const SurfaceOcclusionParameters& parameters,
  float* out, const Execution& execution = {});
Status surfaceAmbientOcclusion(SurfacePyramid& pyramid, const VolumeView& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing, const float* points,
  const float* normals, std::int64_t count, const SurfaceOcclusionParameters& parameters,
  float* out, const Execution& execution = {});
Status surfaceShadow(SurfacePyramid& pyramid, const double* points, const double* normals,
  std::int64_t count, const std::array<double, 3>& lightDirection,
  const SurfaceOcclusionParameters& parameters, float* out, const Execution& execution = {});
Status surfaceShadow(SurfacePyramid& pyramid, const float* points, const float* normals,
  std::int64_t count, const std::array<double, 3>& lightDirection,
  const SurfaceOcclusionParameters& parameters, float* out, const Execution& execution = {});

/// surfaceAmbientOcclusion and surfaceShadow of the same points on a SurfacePyramid in one
/// sweep: each tile both reach is built once (separately, the second query builds again
/// the tiles the first released). The same numbers as the two calls.
Status surfaceOcclusionAndShadow(SurfacePyramid& pyramid, const VolumeView& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing, const double* points,
  const double* normals, std::int64_t count, const std::array<double, 3>& lightDirection,
  const SurfaceOcclusionParameters& parameters, float* occlusion, float* shadow,
  const Execution& execution = {});
Status surfaceOcclusionAndShadow(SurfacePyramid& pyramid, const VolumeView& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing, const float* points,
  const float* normals, std::int64_t count, const std::array<double, 3>& lightDirection,
  const SurfaceOcclusionParameters& parameters, float* occlusion, float* shadow,
  const Execution& execution = {});

/// Trilinear sample of a level's mean and variance at a world position (clamped to the
/// level's bounds).
void sampleLevel(
  const MomentLevel& level, const std::array<double, 3>& position, double& mean, double& variance);

/// Trilinear sample of the volume (any scalar type) at a world position, clamped to the
/// volume: voxel (0, 0, 0) at `origin`, `spacing` per axis. The interpolation of the
/// half-voxel-inside query.
double sampleVolume(const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const std::array<double, 3>& position);

} // namespace vao
