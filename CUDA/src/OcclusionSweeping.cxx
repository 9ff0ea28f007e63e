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
#include "SweepingCore.h"
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
namespace detail
{
namespace sweeping
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

bool finitePositive(double value)
{
  return std::isfinite(value) && value > 0.0;
}

} // namespace

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

namespace
{

/// D of the grid points next to the iso surface: on every axis edge whose ends straddle
/// the iso value, the linearly interpolated distance to the crossing (the minimum over the
/// point's edges); these points are fixed. All others get +-infinity. The distance is
/// computed from each point's own end of the edge, so that mirrored data give mirrored
/// bits. Returns the number of fixed points.
template <class T>
std::int64_t initialiseDistanceOf(const VolumeView& view, const Index3& scalarOffset,
  const SweepLayout& layout, const SweepParameters& p, float* distance, int threads)
{
  const detail::TypedVolume<T> volume(view);
  const double c = p.isoValue;
  const bool above = p.insideIsAbove;
  auto inside = [c, above](double v) { return above ? v > c : v < c; };
  const Index3& extent = view.dims;
  const std::int64_t steps[3] = { 1, extent[0], extent[0] * extent[1] };
  const std::array<double, 3>& h = layout.storage.h;
  std::atomic<std::int64_t> fixedCount{ 0 };
  detail::parallelChunks(
    layout.size[2], threads,
    [&](std::int64_t z0, std::int64_t z1, bool) {
      std::int64_t local = 0;
      for (std::int64_t z = z0; z < z1; ++z)
        for (std::int64_t y = 0; y < layout.size[1]; ++y)
          for (std::int64_t x = 0; x < layout.size[0]; ++x)
          {
            const std::int64_t position[3] = { x + scalarOffset[0], y + scalarOffset[1],
              z + scalarOffset[2] };
            const std::int64_t i = volume.index(position[0], position[1], position[2]);
            const double v = static_cast<double>(volume.data[i * volume.stride]);
            const bool in = inside(v);
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
                  nearest = std::min(nearest, (c - v) / (w - v) * h[a]);
              }
            const bool isFixed = nearest < std::numeric_limits<double>::infinity();
            const float magnitude = isFixed ? static_cast<float>(nearest) : kInfinity;
            const std::int64_t o = layout.index(x, y, z);
            distance[o] = in ? -magnitude : magnitude;
            local += isFixed;
          }
      fixedCount += local;
    },
    threads);
  return fixedCount.load();
}

} // namespace

std::int64_t initialiseDistance(const VolumeView& scalars, const Index3& scalarOffset,
  const SweepLayout& layout, const SweepParameters& p, float* distance, int threads)
{
  return detail::dispatchScalarType(scalars.type, [&](auto tag) {
    return initialiseDistanceOf<decltype(tag)>(scalars, scalarOffset, layout, p, distance, threads);
  });
}

void FixedMask::build(const float* distance, std::int64_t count, int threads)
{
  const std::int64_t words = (count + 63) / 64;
  this->Words.assign(static_cast<std::size_t>(words), 0);
  std::uint64_t* out = this->Words.data();
  detail::parallelChunks(
    words, threads,
    [&](std::int64_t w0, std::int64_t w1, bool) {
      for (std::int64_t w = w0; w < w1; ++w)
      {
        std::uint64_t bits = 0;
        const std::int64_t end = std::min<std::int64_t>(64, count - 64 * w);
        for (std::int64_t b = 0; b < end; ++b)
          bits |= std::uint64_t(std::abs(distance[64 * w + b]) < kInfinity) << b;
        out[w] = bits;
      }
    },
    threads);
}

namespace
{

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
/// open sky, D = +inf and V = 1, outside the volume); startD/startV, the x-upwind
/// neighbour of the first voxel (the open sky, or a ghost voxel of a block).
struct RowView
{
  float* d;
  const float* dy;
  const float* dz;
  const std::uint64_t* fixedWords; // FixedMask, bit fixedIndex + x for voxel x of the row
  std::int64_t fixedIndex;
  float* v;
  const float* vy;
  const float* vz;
  float startD;
  float startV;
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
  float previousD = row.startD; // the x-upwind neighbour
  float previousV = row.startV;
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
    const std::int64_t f = row.fixedIndex + x;
    const bool fixed = (row.fixedWords[f >> 6] >> (f & 63)) & 1u;
    if (!fixed && old > std::min({ ax, ay, az }) + k.lowerBound)
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

struct alignas(64) RowCounter
{
  std::atomic<std::int64_t> done{ 0 };
};

class Sweeper
{
public:
  Sweeper(const SweepLayout& layout, const SweepConstants& constants, float* distance,
    const FixedMask& fixed, VisibilityStore& visibility, int threads)
    : L(layout)
    , G(layout.storage)
    , K(constants)
    , D(distance)
    , Fixed(fixed.words())
    , Vis(visibility)
    , Threads(threads)
    , SkyD(layout.size[0], kInfinity)
    , SkyV(layout.size[0], 1.0f)
  {}

  /// Sweep s over the own voxels. Returns false when cancelled.
  bool sweep(int s, bool visibility, const Execution& execution, RowResult& total)
  {
    const std::int64_t planes = this->L.size[2];
    SweepState state(s, visibility, execution, planes);
    detail::parallelChunks(
      planes, static_cast<int>(planes),
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
    const Index3& n = this->L.size;
    const std::int64_t z = this->L.offset[2] + (state.dir[2] > 0 ? k : n[2] - 1 - k);
    const bool ghosted = this->L.ghosted;
    RowResult& result = state.planeResults[k];
    for (std::int64_t j = 0; j < n[1]; ++j)
    {
      if (k > 0 && !waitForRow(state.rowsDone[k - 1], j, state.control))
      {
        return false;
      }
      const std::int64_t y = this->L.offset[1] + (state.dir[1] > 0 ? j : n[1] - 1 - j);
      const RowResult r = state.rowKernel(
        this->rowView(state, y, z, ghosted || j > 0, ghosted || k > 0), n[0], this->K);
      result.largestChange = std::max(result.largestChange, r.largestChange);
      result.reachedNew = result.reachedNew || r.reachedNew;
      if (state.visibility && !this->Vis.kept)
      {
        float* sum = this->Vis.sum + g.index(this->L.offset[0], y, z);
        const float* v = this->Vis.plane(state.s, z, g) + y * g.nx + this->L.offset[0];
        for (std::int64_t x = 0; x < n[0]; ++x)
        {
          sum[x] += v[x];
        }
      }
      state.rowsDone[k].done.store(j + 1, std::memory_order_release);
    }
    return true;
  }

  /// Row (y, z) (storage coordinates) with its upwind row and plane, or the open sky where
  /// they are outside; the x-upwind neighbour of its first voxel likewise (from storage when
  /// the layout is ghosted).
  RowView rowView(
    const SweepState& state, std::int64_t y, std::int64_t z, bool hasUpwindRow, bool hasUpwindPlane)
  {
    const Grid& g = this->G;
    const std::int64_t sky0 = state.dir[0] > 0 ? 0 : this->L.size[0] - 1; // in the sky rows
    const std::int64_t x0 = this->L.offset[0] + sky0;
    const std::int64_t rowStep = state.dir[1] * g.nx, planeStep = state.dir[2] * g.plane;
    const std::int64_t i = g.index(x0, y, z);
    const bool ghosted = this->L.ghosted;
    RowView row{ this->D + i, hasUpwindRow ? this->D + i - rowStep : this->SkyD.data() + sky0,
      hasUpwindPlane ? this->D + i - planeStep : this->SkyD.data() + sky0, this->Fixed, i, nullptr,
      nullptr, nullptr, ghosted ? this->D[i - state.dir[0]] : kInfinity, 1.0f };
    if (state.visibility)
    {
      const std::int64_t inPlane = y * g.nx + x0;
      row.v = this->Vis.plane(state.s, z, g) + inPlane;
      row.vy = hasUpwindRow ? row.v - rowStep : this->SkyV.data() + sky0;
      row.vz = hasUpwindPlane ? this->Vis.plane(state.s, z - state.dir[2], g) + inPlane
                              : this->SkyV.data() + sky0;
      row.startV = ghosted ? row.v[-state.dir[0]] : 1.0f;
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

  const SweepLayout& L;
  const Grid& G;
  const SweepConstants& K;
  float* D;
  const std::uint64_t* Fixed;
  VisibilityStore& Vis;
  int Threads;
  std::vector<float> SkyD;
  std::vector<float> SkyV;
};

// ---------------------------------------------------------------------------------------
// Combination into the outputs

/// N at own voxel (x, y, z): the normalised central-difference gradient of D (one-sided at
/// the whole volume's borders; a block reads its ghost layer elsewhere), pointing outward.
std::array<double, 3> distanceNormal(
  const float* d, const SweepLayout& layout, std::int64_t x, std::int64_t y, std::int64_t z)
{
  const Grid& g = layout.storage;
  const std::int64_t position[3] = { layout.begin[0] + x, layout.begin[1] + y,
    layout.begin[2] + z };
  const Index3& extent = layout.whole;
  const std::int64_t step[3] = { 1, g.nx, g.plane };
  const std::int64_t i = layout.index(x, y, z);
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
  const SweepLayout& layout;
  const SweepParameters& p;
  const SweepOutput& out;
  const float* distance;
  const VisibilityStore& vis;
  double maskCount;

  /// The unclamped A of own voxel (x, y, z), storage index i.
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
    allGeometryTerms(distanceNormal(this->distance, this->layout, x, y, z), twoSided, g);
    double sum = 0.0;
    for (int s = 0; s < 8; ++s)
      if (this->p.octantMask[s])
        sum += this->vis.field[s][i] * g[s];
    return sum / (twoSided ? 2.0 * kPi : kPi);
  }

  void plane(std::int64_t z) const
  {
    const double exponent = 1.0 / this->p.gamma;
    const Index3& n = this->layout.size;
    for (std::int64_t y = 0; y < n[1]; ++y)
      for (std::int64_t x = 0; x < n[0]; ++x)
      {
        const std::int64_t i = this->layout.index(x, y, z);
        const std::int64_t o = (z * n[1] + y) * n[0] + x;
        if (this->out.octantVisibility)
        {
          for (int s = 0; s < 8; ++s)
            this->out.octantVisibility[8 * o + s] = this->vis.field[s][i];
        }
        if (this->out.ambientOcclusion)
        {
          double a = std::min(1.0, std::max(0.0, this->occlusion(i, x, y, z)));
          if (exponent != 1.0)
          {
            a = exponent == 0.5 ? std::sqrt(a) : std::pow(a, exponent); // the paper's gamma 2, fast
          }
          this->out.ambientOcclusion[o] = static_cast<float>(a);
        }
      }
  }
};

} // namespace

// ---------------------------------------------------------------------------------------
// Stages (SweepingCore.h)

void fillWithoutSurface(
  const SweepLayout& layout, bool allInside, float* distance, VisibilityStore& vis, double maskCount)
{
  const double diagonal = Grid(layout.whole, layout.storage.h).diagonal();
  const float d = static_cast<float>(allInside ? -diagonal : diagonal);
  const float v = allInside ? 0.0f : 1.0f;
  const std::int64_t count = layout.storage.count;
  std::fill(distance, distance + count, d);
  if (vis.kept)
  {
    for (float* field : vis.field)
      if (field)
        std::fill(field, field + count, v);
  }
  else if (vis.sum)
  {
    std::fill(vis.sum, vis.sum + count, static_cast<float>(v * maskCount));
  }
}

Status runPasses(const SweepLayout& layout, const SweepParameters& p, float* distance,
  const FixedMask& fixed, VisibilityStore& vis, int threads, const Execution& execution,
  SweepReport& report)
{
  const SweepConstants constants(layout.storage.h, p.opacity);
  Sweeper sweeper(layout, constants, distance, fixed, vis, threads);
  for (int pass = 0; pass < p.iterations; ++pass)
  {
    if (vis.sum)
    {
      // V is recomputed in every pass
      std::fill(vis.sum, vis.sum + layout.storage.count, 0.0f);
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

Status combine(const SweepLayout& layout, const SweepParameters& p, const SweepOutput& out,
  const float* distance, const VisibilityStore& vis, double maskCount, int threads,
  const Execution& execution)
{
  if (!out.ambientOcclusion && !out.octantVisibility)
  {
    return Status::success();
  }
  const Combiner combiner{ layout, p, out, distance, vis, maskCount };
  const std::int64_t planes = layout.size[2];
  detail::LoopControl control(execution, planes);
  detail::parallelChunks(
    planes, threads,
    [&](std::int64_t z0, std::int64_t z1, bool caller) {
      for (std::int64_t z = z0; z < z1 && !control.stopped(); ++z)
      {
        combiner.plane(z);
        control.advance(1, caller);
      }
    },
    threads);
  return control.stopped() ? Status::cancelled() : Status::success();
}

} // namespace sweeping
} // namespace detail

// ---------------------------------------------------------------------------------------
// The whole volume

namespace
{

using namespace detail::sweeping;

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

Status occlusionSweeping(const VolumeView& volume, const std::array<double, 3>& spacing,
  const SweepParameters& p, const SweepOutput& out, const Execution& execution, SweepReport& report)
{
  const SweepLayout layout = SweepLayout::wholeVolume(volume.dims, spacing);
  const Grid& grid = layout.storage;
  const int threads = detail::resolveThreadCount(execution.threads);
  std::vector<float> ownDistance;
  float* distance = out.signedDistance;
  if (!distance)
  {
    ownDistance.resize(static_cast<std::size_t>(grid.count));
    distance = ownDistance.data();
  }
  const int sweepThreads = static_cast<int>(std::min<std::int64_t>(threads, grid.nz));
  VisibilityStore vis = planVisibility(grid, p, out, sweepThreads);
  double maskCount = 0.0;
  for (bool m : p.octantMask)
    maskCount += m;

  const std::int64_t fixedCount = initialiseDistance(volume, { 0, 0, 0 }, layout, p, distance, threads);
  FixedMask fixed;
  fixed.build(distance, grid.count, threads);
  report.surfaceFound = fixedCount > 0;
  report.passes = 0;
  report.lastChange = 0.0;
  if (report.surfaceFound)
  {
    const Status status = runPasses(layout, p, distance, fixed, vis, sweepThreads,
      detail::stageExecution(execution, 0.0, 0.95), report);
    if (!status.ok)
    {
      return status;
    }
  }
  else
  {
    fillWithoutSurface(layout, distance[0] < 0.0f, distance, vis, maskCount);
  }
  const Status status = combine(layout, p, out, distance, vis, maskCount, threads,
    detail::stageExecution(execution, 0.95, 1.0));
  if (!status.ok)
  {
    return status;
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
  detail::sweeping::allGeometryTerms(
    detail::sweeping::unitNormal(normal[0], normal[1], normal[2]), twoSided, g);
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
