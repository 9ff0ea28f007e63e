// What the surface queries (SurfaceSampling.cxx) share between marking the tiles their
// samples reach and sampling: the points in batches of kLanes, with the same positions
// and unit normals either way, and the box the shadow march stays in.
#pragma once

#include "cpu/common/Parallel.h"
#include "cpu/moment_pyramid/LevelGrid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>

namespace vao
{
namespace detail
{

/// Which points a loop takes: [begin, begin + count) of `order` (a permutation of the
/// points), or of the points themselves without one.
struct PointRange
{
  const std::uint32_t* order = nullptr;
  std::int64_t begin = 0;
  std::int64_t count = 0;

  std::int64_t operator[](std::int64_t i) const { return order ? order[begin + i] : begin + i; }
};

/// kLanes points at a time (the last batch padded with copies of its last point): their
/// indices, positions, unit normals and queries, structure of arrays.
struct PointLanes
{
  int used = 0; // real points in the batch
  std::int64_t index[kLanes];
  double x[kLanes], y[kLanes], z[kLanes];
  double nx[kLanes], ny[kLanes], nz[kLanes];
  double query[kLanes];

  template <class P>
  PointLanes(const P* points, const P* normals, const PointRange& range, std::int64_t batch)
    : used(static_cast<int>(std::min<std::int64_t>(kLanes, range.count - batch * kLanes)))
  {
    for (int k = 0; k < kLanes; ++k)
    {
      const std::int64_t i = range[batch * kLanes + std::min(k, this->used - 1)];
      const double p[3] = { static_cast<double>(points[3 * i]),
        static_cast<double>(points[3 * i + 1]), static_cast<double>(points[3 * i + 2]) };
      const double n[3] = { static_cast<double>(normals[3 * i]),
        static_cast<double>(normals[3 * i + 1]), static_cast<double>(normals[3 * i + 2]) };
      const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
      this->index[k] = i;
      this->x[k] = p[0];
      this->y[k] = p[1];
      this->z[k] = p[2];
      this->nx[k] = n[0] / length;
      this->ny[k] = n[1] / length;
      this->nz[k] = n[2] / length;
    }
  }

  /// The world position at distance d from point k along its normal.
  std::array<double, 3> along(int k, double d) const
  {
    return { this->x[k] + d * this->nx[k], this->y[k] + d * this->ny[k],
      this->z[k] + d * this->nz[k] };
  }

  /// Those positions of every lane, as three arrays (the vector lanes' input).
  void along(double d, double* atX, double* atY, double* atZ) const
  {
    for (int k = 0; k < kLanes; ++k)
    {
      const std::array<double, 3> at = this->along(k, d);
      atX[k] = at[0];
      atY[k] = at[1];
      atZ[k] = at[2];
    }
  }
};

/// f(lanes) for every batch of kLanes points of `range`, on every thread, reporting
/// progress every 64 batches. Returns false when cancelled.
template <class P, class PerBatch>
bool forEachBatch(const P* points, const P* normals, const PointRange& range,
  const Execution& execution, PerBatch&& f)
{
  constexpr int kProgressBatches = 64;
  const std::int64_t batches = (range.count + kLanes - 1) / kLanes;
  const int threads = resolveThreadCount(execution.threads);
  const int chunks =
    static_cast<int>(std::min<std::int64_t>(std::max<std::int64_t>(batches, 1), threads * 8));
  return parallelFor(batches, chunks, threads, execution,
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress)
    {
      for (std::int64_t b = begin; b < end; ++b)
      {
        PointLanes lanes(points, normals, range, b);
        f(lanes);
        if ((b - begin) % kProgressBatches == kProgressBatches - 1 &&
          !progress.advance(kProgressBatches))
        {
          return;
        }
      }
      progress.advance((end - begin) % kProgressBatches);
    });
}

/// Float32 rounding of a coordinate, relative to its magnitude, that the march's box
/// allows beyond its faces: two float ulps at least.
constexpr double kFaceSlack = 2.0 * std::numeric_limits<float>::epsilon();

/// The box the shadow march stays in: level 0's bounds, or the whole volume's when the
/// level is a distributed piece's window, widened by kFaceSlack of its coordinates'
/// magnitude. Surface points come as float32 (VTK's points): one on a face whose
/// coordinate float32 does not hold (an origin of -7.4, a spacing of 0.7) rounds up to an
/// ulp outside it, and its march, starting there, would stop at once (Shadow 1 where the
/// same scene in other units was in shadow). Samples so close outside clamp to the face.
struct MarchBounds
{
  double lo[3], hi[3];

  explicit MarchBounds(const MomentLevel& level)
  {
    const bool window = std::isfinite(level.wholeBounds[0]);
    for (int a = 0; a < 3; ++a)
    {
      this->lo[a] = window ? level.wholeBounds[2 * a] : level.origin[a];
      this->hi[a] = window ? level.wholeBounds[2 * a + 1]
                           : level.origin[a] + (level.dims[a] - 1) * level.spacing[a];
      const double slack = kFaceSlack * std::max(std::abs(this->lo[a]), std::abs(this->hi[a]));
      this->lo[a] -= slack;
      this->hi[a] += slack;
    }
  }

  double diagonal() const
  {
    double squared = 0.0;
    for (int a = 0; a < 3; ++a)
      squared += (this->hi[a] - this->lo[a]) * (this->hi[a] - this->lo[a]);
    return std::sqrt(squared);
  }

  bool contains(const double* p) const
  {
    return p[0] >= this->lo[0] && p[0] <= this->hi[0] && p[1] >= this->lo[1] &&
      p[1] <= this->hi[1] && p[2] >= this->lo[2] && p[2] <= this->hi[2];
  }
};

} // namespace detail
} // namespace vao
