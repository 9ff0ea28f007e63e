// Occlusion sweeping (Singh, Yuksel & House 2009; the Singh et al. section of METHODS.md):
// fast sweeping of the signed distance with the octant visibility of Eq. 6 carried along
// in the same sweeps, then the per-voxel combination into AmbientOcclusion (Eq. 4/5).
//
// Layout of the work: D is a signed float field (the sign is fixed at initialisation by
// inside(v); the sweeps only lower |D|). A sweep visits z-planes, rows and voxels in its
// direction; every value it needs from upwind is in the previous voxel (kept in
// registers), the previous row, or the previous plane. The result of a sweep does not
// depend on the visiting order as long as every voxel comes after its upwind neighbours,
// so planes run as a pipeline on several threads: plane k may start row j once plane k-1
// has finished row j.
#include "vao/OcclusionSweeping.h"

#include "Parallel.h"
#include "VolumeAccess.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>
#include <new>
#include <sstream>
#include <thread>
#include <vector>

namespace vao
{
namespace
{

constexpr double kPi = 3.14159265358979323846;
constexpr float kInfinity = std::numeric_limits<float>::infinity();

// ---------------------------------------------------------------------------------------
// Geometry term

/// atan2(y, x) for x, y >= 0, to ~1e-10 and a few times faster than std::atan2 (the
/// geometry term needs six of them per voxel). The ratio is reduced to |t| <= tan(pi/8)
/// with atan(r) = pi/4 + atan((r - 1) / (r + 1)), where the odd series converges fast.
double quadrantAngle(double y, double x)
{
  constexpr double kTanPiOver8 = 0.41421356237309503;
  const bool steep = y > x;
  const double lo = steep ? x : y, hi = steep ? y : x;
  if (!(hi > 0.0))
  {
    return 0.0;
  }
  double t = lo / hi;
  double base = 0.0;
  if (t > kTanPiOver8)
  {
    t = (lo - hi) / (lo + hi);
    base = 0.25 * kPi;
  }
  // Terms up to t^21: the first omitted one is below 0.4143^23 / 23 < 1e-10.
  static constexpr double kSeries[11] = { 1.0, -1.0 / 3, 1.0 / 5, -1.0 / 7, 1.0 / 9, -1.0 / 11,
    1.0 / 13, -1.0 / 15, 1.0 / 17, -1.0 / 19, 1.0 / 21 };
  const double t2 = t * t;
  double series = kSeries[10];
  for (int k = 9; k >= 0; --k)
  {
    series = series * t2 + kSeries[k];
  }
  const double angle = base + t * series;
  return steep ? 0.5 * kPi - angle : angle;
}

/// N normalised; a zero or non-finite N (a flat distance field) becomes +z.
std::array<double, 3> unitNormal(double x, double y, double z)
{
  const double length = std::sqrt(x * x + y * y + z * z);
  if (!(length > 0.0) || !std::isfinite(length))
  {
    return { 0.0, 0.0, 1.0 };
  }
  return { x / length, y / length, z / length };
}

/// G_s(N) of all eight octants for a unit N (twoSided: G_s(N) + G_s(-N)).
///
/// Octant s is {w : sign(w) = -sweepDirection(s)}; flipping those signs maps it to the
/// positive octant, so G_s(N) = F(M) with M_i = -dir_i N_i and
/// F(M) = integral over the positive octant of max(M.w, 0) dw. F depends on |N_i| = p_i
/// and on the set of negative components of M:
/// - none: the whole octant is lit, F = M . Phi with the octant's vector irradiance
///   Phi = (pi/4)(1, 1, 1);
/// - only M_k: the octant clipped by M.w = 0 is the quadrilateral x_i, x_j, p_jk, p_ki;
///   Lambert's formula (1/2) sum_e theta_e (M . n_e) over its edges (normals x_k, x_i,
///   x_j, and M itself on the cut, whose arc is atan2(p_k, p_i p_j) for a unit M) gives
///   F = (1/2)(-(pi/2) p_k + p_i atan2(p_j, p_k) + p_j atan2(p_i, p_k) + atan2(p_k, p_i p_j));
/// - all but M_k: F(M) = F(-M) + M . Phi, because max(t, 0) - max(-t, 0) = t;
/// - all: 0.
/// The eight values of F are tabulated by that set (bit i: M_i < 0), so that each octant
/// is a lookup.
void allGeometryTerms(const std::array<double, 3>& n, bool twoSided, double g[8])
{
  const double p[3] = { std::abs(n[0]), std::abs(n[1]), std::abs(n[2]) };
  double angle[3][3] = {}; // angle[i][k] = atan2(p_i, p_k); the pair sums to pi/2
  for (int i = 0; i < 3; ++i)
    for (int k = i + 1; k < 3; ++k)
    {
      angle[i][k] = quadrantAngle(p[i], p[k]);
      angle[k][i] = 0.5 * kPi - angle[i][k];
    }
  double irradiance[8]; // M . Phi by the set of negative components
  for (int m = 0; m < 8; ++m)
  {
    irradiance[m] =
      0.25 * kPi * (((m & 1) ? -p[0] : p[0]) + ((m & 2) ? -p[1] : p[1]) + ((m & 4) ? -p[2] : p[2]));
  }
  double f[8];
  f[0] = irradiance[0];
  f[7] = 0.0;
  for (int k = 0; k < 3; ++k)
  {
    const int i = (k + 1) % 3, j = (k + 2) % 3;
    const int only = 1 << k, allBut = 7 ^ only;
    f[only] = 0.5 *
      (-0.5 * kPi * p[k] + p[i] * angle[j][k] + p[j] * angle[i][k] +
        quadrantAngle(p[k], p[i] * p[j]));
    f[allBut] = irradiance[allBut] + f[only];
  }
  // M_i = -dir_i N_i < 0: N_i > 0 on a + axis of the sweep (bit i of s clear), N_i < 0 on a - axis.
  const int positive = (n[0] > 0) | (n[1] > 0) << 1 | (n[2] > 0) << 2;
  const int negative = (n[0] < 0) | (n[1] < 0) << 1 | (n[2] < 0) << 2;
  for (int s = 0; s < 8; ++s)
  {
    const int m = ((~s & positive) | (s & negative)) & 7;
    g[s] = twoSided ? 2.0 * f[m] - irradiance[m] : f[m]; // F(-M) = F(M) - M . Phi
  }
}

// ---------------------------------------------------------------------------------------
// Problem set-up

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
  {}
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

bool finitePositive(double value)
{
  return std::isfinite(value) && value > 0.0;
}

Status validateSweep(const VolumeView& volume, const std::array<double, 3>& spacing,
  const SweepParameters& p, const SweepOutput& output)
{
  std::ostringstream why;
  const Index3& d = volume.dims;
  const bool anyOctant =
    std::find(p.octantMask.begin(), p.octantMask.end(), true) != p.octantMask.end();
  if (!volume.data || d[0] <= 0 || d[1] <= 0 || d[2] <= 0)
  {
    why << "the volume is empty (" << d[0] << " x " << d[1] << " x " << d[2] << " voxels)";
  }
  else if (volume.voxelStride < 1)
  {
    why << "the voxel stride must be at least 1 (got " << volume.voxelStride << ")";
  }
  else if (d[0] < 2 || d[1] < 2 || d[2] < 2)
  {
    why << "occlusion sweeping needs a 3-D volume with at least 2 voxels per axis (got " << d[0]
        << " x " << d[1] << " x " << d[2] << ")";
  }
  else if (!finitePositive(spacing[0]) || !finitePositive(spacing[1]) ||
    !finitePositive(spacing[2]))
  {
    why << "the spacing must be finite and positive (got " << spacing[0] << ", " << spacing[1]
        << ", " << spacing[2] << ")";
  }
  else if (!std::isfinite(p.isoValue))
  {
    why << "the iso value must be a finite number (got " << p.isoValue << ")";
  }
  else if (p.iterations < 1)
  {
    why << "at least one pass of the 8 sweeps is needed (iterations = " << p.iterations << ")";
  }
  else if (!std::isfinite(p.tolerance) || p.tolerance < 0.0)
  {
    why << "the tolerance must be finite and not negative (got " << p.tolerance << ")";
  }
  else if (!finitePositive(p.gamma))
  {
    why << "gamma must be finite and positive (got " << p.gamma << ")";
  }
  else if (!(p.opacity >= 0.0 && p.opacity <= 1.0))
  {
    why << "the opacity must lie in [0, 1] (got " << p.opacity << ")";
  }
  else if (output.ambientOcclusion && !anyOctant)
  {
    why << "every octant is masked off, so the ambient occlusion is undefined";
  }
  else
  {
    std::int64_t first = -1;
    const std::int64_t bad = countNonFinite(volume, &first);
    if (bad > 0)
    {
      why << "the volume has " << bad << " non-finite value" << (bad == 1 ? "" : "s")
          << " (NaN or infinity), the first at voxel index " << first;
    }
  }
  const std::string message = why.str();
  return message.empty() ? Status::success() : Status::failure(message);
}

// ---------------------------------------------------------------------------------------
// Initialisation

/// D of the grid points next to the iso surface: on every axis edge whose ends straddle
/// the iso value, the linearly interpolated distance to the crossing (the minimum over the
/// point's edges); these points are fixed. All others get +-infinity. The distance is
/// computed from each point's own end of the edge, so that mirrored data give mirrored
/// bits. Returns the number of fixed points.
template <class T>
std::int64_t initialiseDistance(const VolumeView& view, const Grid& grid, const SweepParameters& p,
  float* distance, std::uint8_t* fixed, int threads)
{
  const detail::TypedVolume<T> volume(view);
  const double c = p.isoValue;
  const bool above = p.insideIsAbove;
  auto inside = [c, above](double v) { return above ? v > c : v < c; };
  const std::int64_t steps[3] = { 1, grid.nx, grid.plane };
  std::atomic<std::int64_t> fixedCount{ 0 };
  detail::parallelChunks(
    grid.nz, threads,
    [&](std::int64_t z0, std::int64_t z1, bool) {
      std::int64_t local = 0;
      for (std::int64_t z = z0; z < z1; ++z)
        for (std::int64_t y = 0; y < grid.ny; ++y)
          for (std::int64_t x = 0; x < grid.nx; ++x)
          {
            const std::int64_t i = grid.index(x, y, z);
            const double v = static_cast<double>(volume.data[i * volume.stride]);
            const bool in = inside(v);
            const std::int64_t position[3] = { x, y, z };
            const std::int64_t extent[3] = { grid.nx, grid.ny, grid.nz };
            double nearest = std::numeric_limits<double>::infinity();
            for (int a = 0; a < 3; ++a)
              for (int side = -1; side <= 1; side += 2)
              {
                const std::int64_t q = position[a] + side;
                if (q < 0 || q >= extent[a])
                  continue;
                const double w =
                  static_cast<double>(volume.data[(i + side * steps[a]) * volume.stride]);
                if (inside(w) != in)
                  nearest = std::min(nearest, (c - v) / (w - v) * grid.h[a]);
              }
            const bool isFixed = nearest < std::numeric_limits<double>::infinity();
            const float magnitude = isFixed ? static_cast<float>(nearest) : kInfinity;
            distance[i] = in ? -magnitude : magnitude;
            fixed[i] = isFixed ? 1 : 0;
            local += isFixed;
          }
      fixedCount += local;
    },
    threads);
  return fixedCount.load();
}

// ---------------------------------------------------------------------------------------
// The sweeps

struct SweepConstants
{
  float h[3];       // spacing
  float w[3];       // 1 / h^2
  float lowerBound; // no update lands closer than 1/sqrt(w0 + w1 + w2) to the nearest neighbour
  float invTauH;    // 1 / smallest spacing (Eq. 7)
  float alpha;      // opacity (Eq. 8)

  SweepConstants(const std::array<double, 3>& spacing, double opacity)
  {
    for (int a = 0; a < 3; ++a)
    {
      h[a] = static_cast<float>(spacing[a]);
      w[a] = static_cast<float>(1.0 / (spacing[a] * spacing[a]));
    }
    // A little below the bound, so that rounding never skips a real update.
    lowerBound = static_cast<float>(0.999 /
      std::sqrt(1.0 / (spacing[0] * spacing[0]) + 1.0 / (spacing[1] * spacing[1]) +
        1.0 / (spacing[2] * spacing[2])));
    invTauH = static_cast<float>(1.0 / std::min({ spacing[0], spacing[1], spacing[2] }));
    alpha = static_cast<float>(opacity);
  }

  /// Transmittance of a voxel with signed distance d (Eq. 7), made translucent by Eq. 8.
  float tau(float d) const
  {
    const float opaque = std::min(1.0f, std::max(0.0f, d * invTauH + 0.5f));
    return 1.0f - alpha * (1.0f - opaque);
  }
};

/// The Godunov upwind update (Eq. 1, anisotropic form): the largest u with
/// sum_i max(u - a_i, 0)^2 / h_i^2 = 1, trying the active sets of the 1, 2, 3 smallest a_i.
/// Infinite neighbours need no special case: they never enter an accepted active set.
inline float godunov(float ax, float ay, float az, const SweepConstants& k)
{
  float a[3] = { ax, ay, az };
  float h[3] = { k.h[0], k.h[1], k.h[2] };
  float w[3] = { k.w[0], k.w[1], k.w[2] };
  auto order = [&](int i, int j) {
    if (a[j] < a[i])
    {
      std::swap(a[i], a[j]);
      std::swap(h[i], h[j]);
      std::swap(w[i], w[j]);
    }
  };
  order(0, 1);
  order(1, 2);
  order(0, 1);
  const float u1 = a[0] + h[0];
  if (u1 <= a[1])
  {
    return u1;
  }
  // The quadratics in difference form: no cancellation between large a_i.
  const float d01 = a[1] - a[0];
  float sumW = w[0] + w[1];
  float disc = sumW - w[0] * w[1] * d01 * d01;
  const float u2 = (a[0] * w[0] + a[1] * w[1] + std::sqrt(std::max(0.0f, disc))) / sumW;
  if (u2 <= a[2])
  {
    return u2;
  }
  const float d02 = a[2] - a[0], d12 = a[2] - a[1];
  sumW += w[2];
  disc = sumW - (w[0] * w[1] * d01 * d01 + w[0] * w[2] * d02 * d02 + w[1] * w[2] * d12 * d12);
  return (a[0] * w[0] + a[1] * w[1] + a[2] * w[2] + std::sqrt(std::max(0.0f, disc))) / sumW;
}

/// One row of a sweep. Pointers are at the row's first voxel in sweep order; the row
/// advances by Step (+1 or -1). dy/dz and vy/vz are the upwind row and plane (a row of
/// open sky, D = +inf and V = 1, outside the volume).
struct RowView
{
  float* d;
  const float* dy;
  const float* dz;
  const std::uint8_t* fixed;
  float* v;
  const float* vy;
  const float* vz;
};

struct RowResult
{
  float largestChange = 0.0f; // of finite |D|
  bool reachedNew = false;    // some |D| went from infinity to finite
};

template <int Step, bool Visibility>
RowResult sweepRow(const RowView& row, std::int64_t count, const SweepConstants& k)
{
  RowResult result;
  float previousD = kInfinity; // the x-upwind neighbour, open sky at the row start
  float previousV = 1.0f;
  for (std::int64_t i = 0; i < count; ++i)
  {
    const std::int64_t x = i * Step;
    const float dy = row.dy[x];
    const float dz = row.dz[x];
    if (Visibility)
    {
      // Eq. 6 with the upwind D as this sweep has left it.
      previousV = (previousV * k.tau(previousD) + row.vy[x] * k.tau(dy) + row.vz[x] * k.tau(dz)) *
        (1.0f / 3.0f);
      row.v[x] = previousV;
    }
    float d = row.d[x];
    const float ax = std::abs(previousD), ay = std::abs(dy), az = std::abs(dz);
    const float old = std::abs(d);
    if (!row.fixed[x] && old > std::min({ ax, ay, az }) + k.lowerBound)
    {
      const float candidate = godunov(ax, ay, az, k);
      if (candidate < old)
      {
        if (old < kInfinity)
        {
          result.largestChange = std::max(result.largestChange, old - candidate);
        }
        else
        {
          result.reachedNew = true;
        }
        d = std::copysign(candidate, d);
        row.d[x] = d;
      }
    }
    previousD = d;
  }
  return result;
}

using RowFunction = RowResult (*)(const RowView&, std::int64_t, const SweepConstants&);

RowFunction rowFunction(int xDirection, bool visibility)
{
  if (xDirection > 0)
  {
    return visibility ? &sweepRow<1, true> : &sweepRow<1, false>;
  }
  return visibility ? &sweepRow<-1, true> : &sweepRow<-1, false>;
}

/// Where the octant visibilities live. Kept: one full field per computed octant (for
/// OctantVisibility and the geometry term). Otherwise a sweep needs only its current and
/// previous plane (two alternating planes suffice even with the pipeline, since plane
/// k + 2 writes row j only after plane k + 1 has read row j of plane k), and the masked
/// octants are summed into `sum` as the rows complete.
struct VisibilityStore
{
  std::array<bool, 8> computed{};
  std::array<float*, 8> field{}; // when kept
  std::vector<float> storage;
  // When not kept, a ring of planes. Plane k of a sweep overwrites the slot of plane
  // k - ringPlanes, which must be finished and no longer read (as the upwind plane of
  // k - ringPlanes + 1). With T threads the planes in flight are at most the last T (thread
  // t sweeps planes t, t + T, ... in order, and a plane waits for its upwind one), so T + 1
  // slots are enough; two slots would let a third thread overwrite a row of plane k - 1
  // while plane k - 1 still reads it as its upwind row.
  std::vector<float> ring;
  std::int64_t ringPlanes = 0;
  float* sum = nullptr; // sum of m_s V_s, when not kept
  bool kept = false;

  float* plane(int s, std::int64_t z, const Grid& grid)
  {
    return this->kept ? this->field[s] + z * grid.plane
                      : this->ring.data() + (z % this->ringPlanes) * grid.plane;
  }
};

struct alignas(64) RowCounter
{
  std::atomic<std::int64_t> done{ 0 };
};

class Sweeper
{
public:
  Sweeper(const Grid& grid, const SweepConstants& constants, float* distance,
    const std::uint8_t* fixed, VisibilityStore& visibility, int threads)
    : G(grid)
    , K(constants)
    , D(distance)
    , Fixed(fixed)
    , Vis(visibility)
    , Threads(threads)
    , SkyD(grid.nx, kInfinity)
    , SkyV(grid.nx, 1.0f)
  {}

  /// Sweep s over the whole volume. Returns false when cancelled.
  bool sweep(int s, bool visibility, const Execution& execution, RowResult& total)
  {
    SweepState state(s, visibility, execution, this->G.nz);
    detail::parallelChunks(
      this->G.nz, static_cast<int>(this->G.nz),
      [&](std::int64_t k0, std::int64_t k1, bool caller) {
        for (std::int64_t k = k0; k < k1 && !state.control.stopped(); ++k)
        {
          if (!this->sweepPlane(state, k))
          {
            return;
          }
          state.control.advance(1, caller);
        }
      },
      this->Threads);
    for (const RowResult& r : state.planeResults)
    {
      total.largestChange = std::max(total.largestChange, r.largestChange);
      total.reachedNew = total.reachedNew || r.reachedNew;
    }
    return !state.control.stopped();
  }

private:
  struct SweepState
  {
    int s;
    std::array<int, 3> dir;
    bool visibility;
    RowFunction rowKernel;
    std::vector<RowCounter> rowsDone;    // per plane k (in sweep order): rows finished
    std::vector<RowResult> planeResults; // per plane k
    detail::LoopControl control;

    SweepState(int octant, bool withVisibility, const Execution& execution, std::int64_t planes)
      : s(octant)
      , dir(sweepDirection(octant))
      , visibility(withVisibility)
      , rowKernel(rowFunction(dir[0], withVisibility))
      , rowsDone(static_cast<std::size_t>(planes))
      , planeResults(static_cast<std::size_t>(planes))
      , control(execution, planes)
    {}
  };

  /// Plane k of the sweep (k counts in sweep order). Waits, row by row, for plane k - 1.
  bool sweepPlane(SweepState& state, std::int64_t k)
  {
    const Grid& g = this->G;
    const std::int64_t z = state.dir[2] > 0 ? k : g.nz - 1 - k;
    RowResult& result = state.planeResults[k];
    for (std::int64_t j = 0; j < g.ny; ++j)
    {
      if (k > 0 && !waitForRow(state.rowsDone[k - 1], j, state.control))
      {
        return false;
      }
      const std::int64_t y = state.dir[1] > 0 ? j : g.ny - 1 - j;
      const RowResult r = state.rowKernel(this->rowView(state, y, z, j > 0, k > 0), g.nx, this->K);
      result.largestChange = std::max(result.largestChange, r.largestChange);
      result.reachedNew = result.reachedNew || r.reachedNew;
      if (state.visibility && !this->Vis.kept)
      {
        float* sum = this->Vis.sum + g.index(0, y, z);
        const float* v = this->Vis.plane(state.s, z, g) + y * g.nx;
        for (std::int64_t x = 0; x < g.nx; ++x)
        {
          sum[x] += v[x];
        }
      }
      state.rowsDone[k].done.store(j + 1, std::memory_order_release);
    }
    return true;
  }

  /// Row (y, z) with its upwind row and plane, or the open sky where they are outside.
  RowView rowView(
    const SweepState& state, std::int64_t y, std::int64_t z, bool hasUpwindRow, bool hasUpwindPlane)
  {
    const Grid& g = this->G;
    const std::int64_t x0 = state.dir[0] > 0 ? 0 : g.nx - 1;
    const std::int64_t rowStep = state.dir[1] * g.nx, planeStep = state.dir[2] * g.plane;
    const std::int64_t i = g.index(x0, y, z);
    RowView row{ this->D + i, hasUpwindRow ? this->D + i - rowStep : this->SkyD.data() + x0,
      hasUpwindPlane ? this->D + i - planeStep : this->SkyD.data() + x0, this->Fixed + i, nullptr,
      nullptr, nullptr };
    if (state.visibility)
    {
      row.v = this->Vis.plane(state.s, z, g) + y * g.nx + x0;
      row.vy = hasUpwindRow ? row.v - rowStep : this->SkyV.data() + x0;
      row.vz = hasUpwindPlane ? this->Vis.plane(state.s, z - state.dir[2], g) + y * g.nx + x0
                              : this->SkyV.data() + x0;
    }
    return row;
  }

  static bool waitForRow(
    const RowCounter& upwindPlane, std::int64_t j, const detail::LoopControl& control)
  {
    while (upwindPlane.done.load(std::memory_order_acquire) <= j)
    {
      if (control.stopped())
      {
        return false;
      }
      std::this_thread::yield();
    }
    return true;
  }

  const Grid& G;
  const SweepConstants& K;
  float* D;
  const std::uint8_t* Fixed;
  VisibilityStore& Vis;
  int Threads;
  std::vector<float> SkyD;
  std::vector<float> SkyV;
};

// ---------------------------------------------------------------------------------------
// Combination into the outputs

/// N at voxel (x, y, z): the normalised central-difference gradient of D (one-sided at the
/// borders), pointing outward.
std::array<double, 3> distanceNormal(
  const float* d, const Grid& g, std::int64_t x, std::int64_t y, std::int64_t z)
{
  const std::int64_t position[3] = { x, y, z };
  const std::int64_t extent[3] = { g.nx, g.ny, g.nz };
  const std::int64_t step[3] = { 1, g.nx, g.plane };
  const std::int64_t i = g.index(x, y, z);
  double gradient[3];
  for (int a = 0; a < 3; ++a)
  {
    const std::int64_t lo = position[a] > 0 ? -1 : 0;
    const std::int64_t hi = position[a] + 1 < extent[a] ? 1 : 0;
    gradient[a] =
      (static_cast<double>(d[i + hi * step[a]]) - d[i + lo * step[a]]) / ((hi - lo) * g.h[a]);
  }
  return unitNormal(gradient[0], gradient[1], gradient[2]);
}

struct Combiner
{
  const Grid& grid;
  const SweepParameters& p;
  const SweepOutput& out;
  const float* distance;
  const VisibilityStore& vis;
  double maskCount;

  /// The unclamped A of voxel (x, y, z), index i.
  double occlusion(std::int64_t i, std::int64_t x, std::int64_t y, std::int64_t z) const
  {
    if (!this->p.useGeometryTerm)
    {
      if (!this->vis.kept)
      {
        return this->vis.sum[i] / this->maskCount;
      }
      double sum = 0.0;
      for (int s = 0; s < 8; ++s)
        if (this->p.octantMask[s])
          sum += this->vis.field[s][i];
      return sum / this->maskCount;
    }
    const bool twoSided = this->p.opacity < 1.0;
    double g[8];
    allGeometryTerms(distanceNormal(this->distance, this->grid, x, y, z), twoSided, g);
    double sum = 0.0;
    for (int s = 0; s < 8; ++s)
      if (this->p.octantMask[s])
        sum += this->vis.field[s][i] * g[s];
    return sum / (twoSided ? 2.0 * kPi : kPi);
  }

  void plane(std::int64_t z) const
  {
    const double exponent = 1.0 / this->p.gamma;
    for (std::int64_t y = 0; y < this->grid.ny; ++y)
      for (std::int64_t x = 0; x < this->grid.nx; ++x)
      {
        const std::int64_t i = this->grid.index(x, y, z);
        if (this->out.octantVisibility)
        {
          for (int s = 0; s < 8; ++s)
            this->out.octantVisibility[8 * i + s] = this->vis.field[s][i];
        }
        if (this->out.ambientOcclusion)
        {
          double a = std::min(1.0, std::max(0.0, this->occlusion(i, x, y, z)));
          if (exponent != 1.0)
          {
            a = exponent == 0.5 ? std::sqrt(a) : std::pow(a, exponent); // the paper's gamma 2, fast
          }
          this->out.ambientOcclusion[i] = static_cast<float>(a);
        }
      }
  }
};

// ---------------------------------------------------------------------------------------
// Driver

/// What the request needs: the octants whose V is computed, and whether V is kept per
/// octant (OctantVisibility, or the geometry term that needs the final N).
VisibilityStore planVisibility(
  const Grid& grid, const SweepParameters& p, const SweepOutput& out, int sweepThreads)
{
  VisibilityStore vis;
  int computedCount = 0;
  for (int s = 0; s < 8; ++s)
  {
    vis.computed[s] = out.octantVisibility || (out.ambientOcclusion && p.octantMask[s]);
    computedCount += vis.computed[s];
  }
  vis.kept = out.octantVisibility || (out.ambientOcclusion && p.useGeometryTerm);
  if (vis.kept)
  {
    vis.storage.resize(static_cast<std::size_t>(computedCount * grid.count));
    float* next = vis.storage.data();
    for (int s = 0; s < 8; ++s)
      if (vis.computed[s])
      {
        vis.field[s] = next;
        next += grid.count;
      }
  }
  else if (computedCount > 0)
  {
    vis.ringPlanes = std::min<std::int64_t>(grid.nz, sweepThreads + 1);
    vis.ring.resize(static_cast<std::size_t>(vis.ringPlanes * grid.plane));
    vis.sum = out.ambientOcclusion;
  }
  return vis;
}

/// No edge crosses the iso value: D = +-(the volume's diagonal) with the sign of inside,
/// and every octant open (all outside) or closed (all inside), whatever the opacity.
void fillWithoutSurface(
  const Grid& grid, bool allInside, float* distance, VisibilityStore& vis, double maskCount)
{
  const float d = static_cast<float>(allInside ? -grid.diagonal() : grid.diagonal());
  const float v = allInside ? 0.0f : 1.0f;
  std::fill(distance, distance + grid.count, d);
  if (vis.kept)
  {
    for (float* field : vis.field)
      if (field)
        std::fill(field, field + grid.count, v);
  }
  else if (vis.sum)
  {
    std::fill(vis.sum, vis.sum + grid.count, static_cast<float>(v * maskCount));
  }
}

/// Up to p.iterations passes of the 8 sweeps (Table 1 order). With a tolerance, stop after
/// a pass that reached no new voxel and changed no finite |D| by as much as the tolerance.
Status runPasses(Sweeper& sweeper, const Grid& grid, const SweepParameters& p, VisibilityStore& vis,
  const Execution& execution, SweepReport& report)
{
  for (int pass = 0; pass < p.iterations; ++pass)
  {
    if (vis.sum)
    {
      std::fill(vis.sum, vis.sum + grid.count, 0.0f); // V is recomputed in every pass
    }
    RowResult total;
    for (int s = 0; s < 8; ++s)
    {
      const double step = 1.0 / (8.0 * p.iterations);
      const Execution stage =
        detail::stageExecution(execution, (pass * 8 + s) * step, (pass * 8 + s + 1) * step);
      if (!sweeper.sweep(s, vis.computed[s], stage, total))
      {
        return Status::cancelled();
      }
    }
    report.passes = pass + 1;
    report.lastChange = total.largestChange;
    if (p.tolerance > 0.0 && !total.reachedNew && total.largestChange < p.tolerance)
    {
      break;
    }
  }
  return Status::success();
}

Status occlusionSweeping(const VolumeView& volume, const std::array<double, 3>& spacing,
  const SweepParameters& p, const SweepOutput& out, const Execution& execution, SweepReport& report)
{
  const Grid grid(volume.dims, spacing);
  const int threads = detail::resolveThreadCount(execution.threads);
  std::vector<float> ownDistance;
  float* distance = out.signedDistance;
  if (!distance)
  {
    ownDistance.resize(static_cast<std::size_t>(grid.count));
    distance = ownDistance.data();
  }
  std::vector<std::uint8_t> fixed(static_cast<std::size_t>(grid.count));
  const int sweepThreads = static_cast<int>(std::min<std::int64_t>(threads, grid.nz));
  VisibilityStore vis = planVisibility(grid, p, out, sweepThreads);
  double maskCount = 0.0;
  for (bool m : p.octantMask)
    maskCount += m;

  const std::int64_t fixedCount = detail::dispatchScalarType(volume.type, [&](auto tag) {
    return initialiseDistance<decltype(tag)>(volume, grid, p, distance, fixed.data(), threads);
  });
  report.surfaceFound = fixedCount > 0;
  report.passes = 0;
  report.lastChange = 0.0;
  if (report.surfaceFound)
  {
    const SweepConstants constants(spacing, p.opacity);
    Sweeper sweeper(grid, constants, distance, fixed.data(), vis, sweepThreads);
    const Status status =
      runPasses(sweeper, grid, p, vis, detail::stageExecution(execution, 0.0, 0.95), report);
    if (!status.ok)
    {
      return status;
    }
  }
  else
  {
    fillWithoutSurface(grid, distance[0] < 0.0f, distance, vis, maskCount);
  }
  if (out.ambientOcclusion || out.octantVisibility)
  {
    const Combiner combiner{ grid, p, out, distance, vis, maskCount };
    const Execution stage = detail::stageExecution(execution, 0.95, 1.0);
    detail::LoopControl control(stage, grid.nz);
    detail::parallelChunks(
      grid.nz, threads,
      [&](std::int64_t z0, std::int64_t z1, bool caller) {
        for (std::int64_t z = z0; z < z1 && !control.stopped(); ++z)
        {
          combiner.plane(z);
          control.advance(1, caller);
        }
      },
      threads);
    if (control.stopped())
    {
      return Status::cancelled();
    }
  }
  if (execution.progress)
  {
    execution.progress(1.0); // the last chunk may have finished on another thread
  }
  return Status::success();
}

} // namespace

std::array<int, 3> sweepDirection(int octant)
{
  return { (octant & 1) ? -1 : 1, (octant & 2) ? -1 : 1, (octant & 4) ? -1 : 1 };
}

double geometryTerm(int octant, const std::array<double, 3>& normal, bool twoSided)
{
  if (octant < 0 || octant > 7)
  {
    return 0.0;
  }
  double g[8];
  allGeometryTerms(unitNormal(normal[0], normal[1], normal[2]), twoSided, g);
  return g[octant];
}

Status computeOcclusionSweeping(const VolumeView& volume, const std::array<double, 3>& spacing,
  const SweepParameters& parameters, const SweepOutput& output, const Execution& execution,
  SweepReport* report)
{
  const Status status = validateSweep(volume, spacing, parameters, output);
  if (!status.ok)
  {
    return status;
  }
  SweepReport local;
  try
  {
    const Status result =
      occlusionSweeping(volume, spacing, parameters, output, execution, report ? *report : local);
    return result;
  }
  catch (const std::bad_alloc&)
  {
    return Status::failure("not enough memory for the sweeping buffers");
  }
}

} // namespace vao
