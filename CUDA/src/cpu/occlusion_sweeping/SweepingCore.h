// The stages of occlusion sweeping, shared by the whole-volume driver
// computeOcclusionSweeping (OcclusionSweeping.cxx) and the block driver BlockSweeper
// (BlockSweeping.cxx). Where each lives: SweepStages.cxx (checks, initial distance, fixed
// mask, combination), SweepKernel.cxx (the sweeps) with SweepRows.h (their rows),
// SweepGeometryTerm.cxx (G_s(N)).
//
// A SweepLayout says where the swept voxels lie in the arrays (D, fixed, V) and in the whole
// volume. The whole volume: the arrays are the volume, and upwind neighbours outside it are
// the open sky (D = +inf, V = tau = 1). A block: the arrays hold the block's own voxels plus
// a one-voxel ghost layer on every face, the sweeps update only the own voxels, and the
// upwind neighbours outside them are read from the ghost layer (the neighbouring block's
// values, or the open sky written there at the whole volume's border).
#pragma once

#include "vao/OcclusionSweeping.h"
#include "vao/Storage.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace vao
{
namespace detail
{
namespace sweeping
{

struct Grid
{
  std::int64_t nx, ny, nz, plane, count;
  std::array<double, 3> h;

  Grid(const Index3& dims, const std::array<double, 3>& spacing)
    : nx(dims[0])
    , ny(dims[1])
    , nz(dims[2])
    , plane(dims[0] * dims[1])
    , count(dims[0] * dims[1] * dims[2])
    , h(spacing)
  {
  }
  std::int64_t index(std::int64_t x, std::int64_t y, std::int64_t z) const
  {
    return (z * ny + y) * nx + x;
  }
  double diagonal() const
  {
    const double ex = (nx - 1) * h[0], ey = (ny - 1) * h[1], ez = (nz - 1) * h[2];
    return std::sqrt(ex * ex + ey * ey + ez * ez);
  }
};

struct SweepLayout
{
  Grid storage;  // the arrays D, fixed and (kept) V
  Index3 offset; // storage position of the first own voxel
  Index3 size;   // own voxels per axis
  Index3 begin;  // first own voxel in the whole volume
  Index3 whole;  // the whole volume's dimensions
  bool ghosted;  // upwind neighbours outside the own voxels come from storage, not the sky

  /// The whole volume: storage = own voxels, no ghosts.
  static SweepLayout wholeVolume(const Index3& dims, const std::array<double, 3>& spacing)
  {
    return { Grid(dims, spacing), { 0, 0, 0 }, dims, { 0, 0, 0 }, dims, false };
  }
  /// Storage index of own voxel (x, y, z) (own coordinates).
  std::int64_t index(std::int64_t x, std::int64_t y, std::int64_t z) const
  {
    return this->storage.index(x + this->offset[0], y + this->offset[1], z + this->offset[2]);
  }
};

/// Where the octant visibilities live. Kept: one full field per computed octant (for
/// OctantVisibility and the geometry term). Otherwise a sweep needs only its current and
/// previous plane, and the masked octants are summed into `sum` as the rows complete.
struct VisibilityStore
{
  std::array<bool, 8> computed{};
  std::array<float*, 8> field{}; // kept: row (y, z) of field s at field[s] + (z ny + y) rowPitch
  StorageArray<float> storage;   // uninitialised: every sweep writes all of its field
  // Elements from one row of a kept field to the next: the storage's nx, or 8 nx when the
  // fields are the rows of the OctantVisibility output itself (row-interleaved: the eight
  // fields' rows (y, z) lie one after another where the output keeps that row's voxels;
  // combine transposes each row in place). Writing there saves a second volume of eight
  // floats per voxel, and its first touch.
  std::int64_t rowPitch = 0;
  bool inOutput = false;
  // When not kept, a ring of planes (ringPlanesFor). Plane k of a sweep overwrites the slot
  // of plane k - ringPlanes, which must be finished and no longer read (as the upwind plane
  // of k - ringPlanes + 1).
  std::vector<float> ring;
  std::int64_t ringPlanes = 0;
  float* sum = nullptr; // sum of m_s V_s, when not kept (the whole volume only)
  bool kept = false;

  /// Elements between rows y and y + 1 of a plane.
  std::int64_t pitch(const Grid& grid) const { return this->kept ? this->rowPitch : grid.nx; }

  /// Row (y, z) of octant s's field (the ring's slot of plane z when not kept).
  float* row(int s, std::int64_t y, std::int64_t z, const Grid& grid)
  {
    return this->kept ? this->field[s] + (z * grid.ny + y) * this->rowPitch
                      : this->ring.data() + (z % this->ringPlanes) * grid.plane + y * grid.nx;
  }

  /// Keeps every computed octant's field: in `output` (whole-volume sweeps, 8 floats per
  /// voxel, row-interleaved as above), else in storage of its own.
  void keep(const Grid& grid, float* output)
  {
    this->kept = true;
    this->inOutput = output != nullptr;
    this->rowPitch = this->inOutput ? 8 * grid.nx : grid.nx;
    int count = 0;
    for (bool c : this->computed)
      count += c;
    if (!this->inOutput)
      this->storage.resize(static_cast<std::size_t>(count * grid.count));
    float* next = this->inOutput ? output : this->storage.data();
    for (int s = 0; s < 8; ++s)
      if (this->computed[s])
      {
        this->field[s] = next;
        next += this->inOutput ? grid.nx : grid.count;
      }
  }
};

/// Planes one member of the sweeping team sweeps together, a row apart (SweepKernel.cxx).
constexpr int kPlanesTogether = 2;

/// Slots of the ring of visibility planes enough for T sweeping threads. Member t sweeps
/// the groups of kPlanesTogether planes t, t + T, ... in order, and a plane waits for its
/// upwind one, so the planes in flight are at most the last kPlanesTogether * T: with one
/// slot more, no plane overwrites a slot whose plane is still swept (it reads its own
/// rows as upwind rows) or read as an upwind plane.
inline std::int64_t ringPlanesFor(int threads, std::int64_t planes)
{
  return std::min<std::int64_t>(planes, kPlanesTogether * std::int64_t(threads) + 1);
}

/// The unit the sweeps measure distances in: the power of two at or below the smallest
/// spacing. Scaling by a power of two is exact, so the sweeps give the bits they would
/// give in world units, but 1/h^2 and its products stay inside float's range whatever
/// the spacing (at 1e-10, (1/h^2)^2 overflowed and distances were off by voxels).
/// D, the tolerance and the reported changes are converted at the entry points.
double sweepUnit(const std::array<double, 3>& spacing);

/// The spacing in sweep units.
std::array<double, 3> inSweepUnits(const std::array<double, 3>& spacing);

/// The spacings the sweeps accept: their float distances stay normal and finite.
constexpr double kSmallestSpacing = 1e-30;
constexpr double kLargestSpacing = 1e30;

/// Rejects bad spacings and parameters (cheap: no pass over the data).
Status validateSweepParameters(
  const std::array<double, 3>& spacing, const SweepParameters& p, const SweepOutput& output);

/// validateSweepParameters, plus the volume: at least 2 voxels per axis, finite values
/// (one parallel pass).
Status validateSweep(const VolumeView& volume, const std::array<double, 3>& spacing,
  const SweepParameters& p, const SweepOutput& output);

/// N normalised; a zero or non-finite N (a flat distance field) becomes +z.
std::array<double, 3> unitNormal(double x, double y, double z);

/// G_s(N) of all eight octants for a unit N (twoSided: G_s(N) + G_s(-N)).
void allGeometryTerms(const std::array<double, 3>& n, bool twoSided, double g[8]);

/// Initial D of the own voxels, from scalars whose voxel scalarOffset is own voxel
/// (0, 0, 0): an edge to a scalar neighbour is considered wherever the scalars have one.
/// The voxels next to the surface get a finite D and are fixed; all others +-infinity.
/// Returns the number of fixed voxels.
std::int64_t initialiseDistance(const VolumeView& scalars, const Index3& scalarOffset,
  const SweepLayout& layout, const SweepParameters& p, float* distance, int threads);

/// One bit per storage voxel: the fixed voxels, whose D the sweeps never change. Bits,
/// not bytes: 1/16 of an int16 volume instead of 1/2 of working memory.
/// Built from D right after initialiseDistance, where they are exactly the finite values
/// (the others, ghosts included, are +-infinity).
class FixedMask
{
public:
  void build(const float* distance, std::int64_t count, int threads);
  const std::uint64_t* words() const { return this->Words.data(); }

private:
  std::vector<std::uint64_t> Words;
};

/// Up to p.iterations passes of the 8 sweeps over the own voxels (Table 1 order); with a
/// tolerance, stops after a pass that reached no new voxel and changed no finite |D| by as
/// much as the tolerance. report: passes and lastChange.
Status runPasses(const SweepLayout& layout, const SweepParameters& p, float* distance,
  const FixedMask& fixed, VisibilityStore& vis, int threads, const Execution& execution,
  SweepReport& report);

/// No edge of the whole volume crosses the iso value: D = +-(the whole volume's diagonal)
/// with the sign of inside, every octant open (all outside) or closed (all inside).
void fillWithoutSurface(const SweepLayout& layout, bool allInside, float* distance,
  VisibilityStore& vis, double maskCount);

/// Writes the outputs of the own voxels (x fastest over layout.size): OctantVisibility and
/// AmbientOcclusion (not D). N of the geometry term: central differences of D, one-sided
/// only at the whole volume's border.
Status combine(const SweepLayout& layout, const SweepParameters& p, const SweepOutput& out,
  const float* distance, const VisibilityStore& vis, double maskCount, int threads,
  const Execution& execution);

} // namespace sweeping
} // namespace detail
} // namespace vao
