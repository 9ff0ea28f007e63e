// The rows of the occlusion sweeps: the Godunov update of the signed distance (Eq. 1) with
// the octant visibility of Eq. 6 carried along, voxel by voxel in a row's sweep order.
// Sweeper (SweepKernel.cxx) hands them out plane by plane.
#pragma once

#include "cpu/simd/CpuDispatch.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>

namespace vao
{
namespace detail
{
namespace sweeping
{

constexpr float kInfinity = std::numeric_limits<float>::infinity();

struct SweepConstants
{
  float h[3];       // spacing
  float w[3];       // 1 / h^2
  float lowerBound; // no update lands closer than 1/sqrt(w0 + w1 + w2) to the nearest neighbour
  float invTauH;    // 1 / smallest spacing (Eq. 7)
  float alphaThird; // opacity (Eq. 8) / 3
  float thirdClear; // (1 - opacity) / 3

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
    alphaThird = static_cast<float>(opacity / 3.0);
    thirdClear = static_cast<float>((1.0 - opacity) / 3.0);
  }

  /// A third of the transmittance of a voxel with signed distance d (Eq. 7), made
  /// translucent by Eq. 8: 1/3 - alpha/3 + alpha/3 * opaque. Eq. 6's mean of three then
  /// needs no multiply after the sum, which shortens the chain from voxel to voxel.
  float tauThird(float d) const
  {
    const float opaque = std::min(1.0f, std::max(0.0f, d * invTauH + 0.5f));
    return alphaThird * opaque + thirdClear;
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
  auto order = [&](int i, int j)
  {
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
/// neighbour of the first voxel (the open sky, or a ghost voxel of a block). scratch:
/// UpwindTerms::kRows rows of the row's length, for its upwind terms.
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
  float* scratch;
};

struct RowResult
{
  float largestChange = 0.0f; // of finite |D|
  bool reachedNew = false;    // some |D| went from infinity to finite
};

/// What each voxel of a row takes from its upwind row and plane, and the transmittance
/// of its D as the sweep finds it: nothing there depends on the row's own x chain, so it
/// is computed for the whole row first, in vector registers, and the serial loop keeps
/// only the chain (Eq. 6's multiply-add, the Godunov update). Indexed like the row's
/// voxels: element x at the returned pointers' [x].
struct UpwindTerms
{
  float* nearest; // min(|dy|, |dz|)
  float* inflow;  // Eq. 6's terms of the upwind row and plane: vy tau/3(dy) + vz tau/3(dz)
  float* tau;     // tau/3(d), d before this row's update
  static constexpr int kRows = 3; // of RowView::scratch

  template <int Step, bool Visibility>
  static UpwindTerms of(const RowView& row, std::int64_t count, const SweepConstants& k)
  {
    // In memory order, from the row's lowest address.
    const std::int64_t low = Step > 0 ? 0 : -(count - 1);
    float* __restrict nearest = row.scratch;
    float* __restrict inflow = row.scratch + count;
    float* __restrict tau = row.scratch + 2 * count;
    const float* __restrict d = row.d + low;
    const float* __restrict dy = row.dy + low;
    const float* __restrict dz = row.dz + low;
    for (std::int64_t i = 0; i < count; ++i)
      nearest[i] = std::min(std::abs(dy[i]), std::abs(dz[i]));
    if (Visibility)
    {
      const SweepConstants c = k; // a copy the stores cannot alias
      const float* __restrict vy = row.vy + low;
      const float* __restrict vz = row.vz + low;
      for (std::int64_t i = 0; i < count; ++i)
      {
        inflow[i] = vy[i] * c.tauThird(dy[i]) + vz[i] * c.tauThird(dz[i]);
        tau[i] = c.tauThird(d[i]);
      }
    }
    return { nearest - low, inflow - low, tau - low };
  }
};

/// One row's pass through the serial loop: the x-upwind neighbour's D, V and tau/3 carried
/// from voxel to voxel (the chain), the rest read from the row's UpwindTerms.
template <int Step, bool Visibility>
struct RowChain
{
  const RowView& row;
  UpwindTerms upwind;
  float previousD; // the x-upwind neighbour's
  float previousV;
  float previousTau;
  RowResult result;

  RowChain(const RowView& r, std::int64_t count, const SweepConstants& k)
    : row(r)
    , upwind(UpwindTerms::of<Step, Visibility>(r, count, k))
    , previousD(r.startD)
    , previousV(r.startV)
    , previousTau(k.tauThird(r.startD))
  {
  }

  /// Voxel i of the row in sweep order.
  VAO_ALWAYS_INLINE void step(std::int64_t i, const SweepConstants& k)
  {
    const std::int64_t x = i * Step;
    if (Visibility)
    {
      // Eq. 6 with the upwind D as this sweep has left it.
      this->previousV = this->previousV * this->previousTau + this->upwind.inflow[x];
      this->row.v[x] = this->previousV;
      this->previousTau = this->upwind.tau[x];
    }
    float d = this->row.d[x];
    const float ax = std::abs(this->previousD);
    const float old = std::abs(d);
    const std::int64_t f = this->row.fixedIndex + x;
    const bool fixed = (this->row.fixedWords[f >> 6] >> (f & 63)) & 1u;
    if (!fixed && old > std::min(ax, this->upwind.nearest[x]) + k.lowerBound)
    {
      const float candidate = godunov(ax, std::abs(this->row.dy[x]), std::abs(this->row.dz[x]), k);
      if (candidate < old)
      {
        if (old < kInfinity)
        {
          this->result.largestChange = std::max(this->result.largestChange, old - candidate);
        }
        else
        {
          this->result.reachedNew = true;
        }
        d = std::copysign(candidate, d);
        this->row.d[x] = d;
        if (Visibility)
          this->previousTau = k.tauThird(d);
      }
    }
    this->previousD = d;
  }
};

/// One row, or two rows that do not depend on each other (rows of neighbouring planes,
/// the second one row behind) interleaved voxel by voxel: each row's loop is bound by the
/// latency of its chain (the Godunov update's square root and division), and two chains
/// in one loop keep the core busy while either waits.
template <int Step, bool Visibility>
void sweepRows(const RowView* rows, int rowCount, std::int64_t count, const SweepConstants& k,
  RowResult* results)
{
  RowChain<Step, Visibility> first(rows[0], count, k);
  if (rowCount == 2)
  {
    RowChain<Step, Visibility> second(rows[1], count, k);
    for (std::int64_t i = 0; i < count; ++i)
    {
      first.step(i, k);
      second.step(i, k);
    }
    results[1] = second.result;
  }
  else
  {
    for (std::int64_t i = 0; i < count; ++i)
      first.step(i, k);
  }
  results[0] = first.result;
}

using RowFunction = void (*)(const RowView*, int, std::int64_t, const SweepConstants&, RowResult*);

inline RowFunction rowFunction(int xDirection, bool visibility)
{
  if (xDirection > 0)
  {
    return visibility ? &sweepRows<1, true> : &sweepRows<1, false>;
  }
  return visibility ? &sweepRows<-1, true> : &sweepRows<-1, false>;
}

} // namespace sweeping
} // namespace detail
} // namespace vao
