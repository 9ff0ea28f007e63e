// The separable box statistics, streamed slice by slice along z.
//
// Sums: each thread owns a chunk of output slices and keeps the 3-D box sums of v and v^2
// for the current slice as a plane. Moving to the next slice adds the 2-D box sum of the
// slice that enters the window and subtracts the one that leaves; both are done in one
// x/y pass over the difference of the two slices (box sums are linear). Per voxel and
// slice this is O(1) whatever the radius, and only the input is read from memory and the
// output written: the planes stay in cache.
//
// Minimum and maximum (needed by CDF Reconstruction and the statistics) are not
// invertible, so they take three van Herk passes (x and y per slice, then z per row).
#pragma once

#include "CpuDispatch.h"
#include "Parallel.h"
#include "SlidingExtremum.h"
#include "VolumeAccess.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace vao
{
namespace detail
{

/// Region geometry shared by the passes: spans read along each axis.
struct BoxGeometry
{
  Index3 dims;
  Region region;
  Radius radius;
  AxisSpan xs, ys, zs;

  BoxGeometry(const Index3& volumeDims, const Region& outputRegion, const Radius& r)
    : dims(volumeDims)
    , region(outputRegion)
    , radius(r)
    , xs(readSpan(outputRegion.begin[0], outputRegion.size[0], r.x, volumeDims[0]))
    , ys(readSpan(outputRegion.begin[1], outputRegion.size[1], r.y, volumeDims[1]))
    , zs(readSpan(outputRegion.begin[2], outputRegion.size[2], r.z, volumeDims[2]))
  {
  }

  std::int64_t planeSize() const { return region.size[0] * region.size[1]; }
  /// Clipped window sizes along x and y of every region column and row.
  std::vector<std::int64_t> windowCounts(int axis) const
  {
    const int r = axis == 0 ? radius.x : (axis == 1 ? radius.y : radius.z);
    std::vector<std::int64_t> counts(static_cast<std::size_t>(region.size[axis]));
    for (std::int64_t i = 0; i < region.size[axis]; ++i)
    {
      counts[i] = clippedWindowCount(region.begin[axis] + i, r, dims[axis]);
    }
    return counts;
  }
};

/// One row of the y pass: plane += run (when plane is not null), then the running column
/// sums move on: run = (run + entering) - leaving, in that order (the rounding of double
/// sums is that of the scalar code it replaced). Compiled for AVX2 too (CpuDispatch.h).
template <class Acc>
struct SlideColumns
{
  static VAO_ALWAYS_INLINE void run(Acc* __restrict plane, Acc* __restrict run, const Acc* __restrict entering,
    const Acc* __restrict leaving, std::int64_t n)
  {
    if (plane)
      for (std::int64_t i = 0; i < n; ++i)
        plane[i] += run[i];
    for (std::int64_t i = 0; i < n; ++i)
      run[i] = (run[i] + entering[i]) - leaving[i];
  }
};

/// Box sums of (v - shift) and (v - shift)^2 for one slice of the region at a time.
template <class T>
class MomentPlanes
{
public:
  using Acc = typename MomentTraits<T>::Accumulator;

  MomentPlanes(const TypedVolume<T>& volume, const BoxGeometry& geometry, Acc shift)
    : Volume(volume)
    , Geo(geometry)
    , Shift(shift)
    , Sum(geometry.planeSize())
    , SumSquares(geometry.planeSize())
    , Row1(geometry.xs.size() + 1)
    , Row2(geometry.xs.size() + 1)
    , XBox1(geometry.ys.size() * geometry.region.size[0])
    , XBox2(geometry.ys.size() * geometry.region.size[0])
    , Run1(geometry.region.size[0])
    , Run2(geometry.region.size[0])
    , Zeros(geometry.region.size[0], Acc(0))
  {
  }

  /// Sets the planes to the box sums of output slice z (window clipped to the volume).
  void startAt(std::int64_t z)
  {
    std::fill(this->Sum.begin(), this->Sum.end(), Acc(0));
    std::fill(this->SumSquares.begin(), this->SumSquares.end(), Acc(0));
    const std::int64_t lo = std::max<std::int64_t>(0, z - this->Geo.radius.z);
    const std::int64_t hi = std::min<std::int64_t>(this->Geo.dims[2] - 1, z + this->Geo.radius.z);
    for (std::int64_t s = lo; s <= hi; ++s)
    {
      this->addSliceDifference(s, -1);
    }
  }

  /// Moves the planes from output slice z to z + 1.
  void advanceFrom(std::int64_t z)
  {
    const std::int64_t entering = z + this->Geo.radius.z + 1;
    const std::int64_t leaving = z - this->Geo.radius.z;
    this->addSliceDifference(
      entering < this->Geo.dims[2] ? entering : -1, leaving >= 0 ? leaving : -1);
  }

  const Acc* sum() const { return this->Sum.data(); }
  const Acc* sumSquares() const { return this->SumSquares.data(); }

private:
  /// Adds the 2-D box sums of slice `entering` and subtracts those of `leaving` (-1: none).
  void addSliceDifference(std::int64_t entering, std::int64_t leaving)
  {
    if (entering < 0 && leaving < 0)
    {
      return;
    }
    const std::int64_t nx = this->Geo.region.size[0];
    for (std::int64_t y = this->Geo.ys.lo; y < this->Geo.ys.hi; ++y)
    {
      this->boxRowDifference(y, entering, leaving);
    }
    this->accumulateColumns(this->XBox1.data(), this->Sum.data(), this->Run1.data(), nx);
    this->accumulateColumns(this->XBox2.data(), this->SumSquares.data(), this->Run2.data(), nx);
  }

  /// x box sums of one row of (entering - leaving), stored at XBox[y - ys.lo].
  void boxRowDifference(std::int64_t y, std::int64_t entering, std::int64_t leaving)
  {
    const std::int64_t span = this->Geo.xs.size();
    const std::int64_t stride = this->Volume.stride;
    Acc* p1 = this->Row1.data();
    Acc* p2 = this->Row2.data();
    const T* in = entering >= 0 ? this->Volume.row(y, entering) + this->Geo.xs.lo * stride : nullptr;
    const T* out = leaving >= 0 ? this->Volume.row(y, leaving) + this->Geo.xs.lo * stride : nullptr;
    // Prefix sums of the difference row; p[i] = sum of the first i values.
    p1[0] = 0;
    p2[0] = 0;
    for (std::int64_t i = 0; i < span; ++i)
    {
      const Acc a = in ? static_cast<Acc>(in[i * stride]) - this->Shift : Acc(0);
      const Acc b = out ? static_cast<Acc>(out[i * stride]) - this->Shift : Acc(0);
      p1[i + 1] = p1[i] + (a - b);
      p2[i + 1] = p2[i] + (a * a - b * b);
    }
    const std::int64_t nx = this->Geo.region.size[0];
    const std::int64_t r = this->Geo.radius.x;
    const std::int64_t x0 = this->Geo.region.begin[0] - this->Geo.xs.lo; // first output in span
    Acc* box1 = this->XBox1.data() + (y - this->Geo.ys.lo) * nx;
    Acc* box2 = this->XBox2.data() + (y - this->Geo.ys.lo) * nx;
    for (std::int64_t i = 0; i < nx; ++i)
    {
      const std::int64_t lo = std::max<std::int64_t>(0, x0 + i - r);
      const std::int64_t hi = std::min<std::int64_t>(span, x0 + i + r + 1);
      box1[i] = p1[hi] - p1[lo];
      box2[i] = p2[hi] - p2[lo];
    }
  }

  /// plane[y] += sum of the x-box rows in y's clipped window, by a running sum over rows.
  void accumulateColumns(const Acc* xbox, Acc* plane, Acc* run, std::int64_t nx)
  {
    const std::int64_t r = this->Geo.radius.y;
    const std::int64_t ny = this->Geo.dims[1];
    const std::int64_t y0 = this->Geo.region.begin[1];
    const std::int64_t yLo = this->Geo.ys.lo;
    const Acc* zeros = this->Zeros.data();
    std::fill(run, run + nx, Acc(0));
    for (std::int64_t y = std::max<std::int64_t>(0, y0 - r); y <= std::min(ny - 1, y0 + r); ++y)
    {
      runRows<SlideColumns<Acc>>(this->Avx2, static_cast<Acc*>(nullptr), run, xbox + (y - yLo) * nx, zeros, nx);
    }
    for (std::int64_t row = 0; row < this->Geo.region.size[1]; ++row)
    {
      // The last row has no next one: its window's entering row may lie past the rows read.
      const std::int64_t y = y0 + row;
      const bool last = row + 1 == this->Geo.region.size[1];
      const std::int64_t entering = y + r + 1, leaving = y - r;
      const Acc* in = !last && entering < ny ? xbox + (entering - yLo) * nx : zeros;
      const Acc* out = !last && leaving >= 0 ? xbox + (leaving - yLo) * nx : zeros;
      runRows<SlideColumns<Acc>>(this->Avx2, plane + row * nx, run, in, out, nx);
    }
  }

  const TypedVolume<T>& Volume;
  const BoxGeometry& Geo;
  Acc Shift;
  std::vector<Acc> Sum, SumSquares;
  std::vector<Acc> Row1, Row2;
  std::vector<Acc> XBox1, XBox2;
  std::vector<Acc> Run1, Run2;
  std::vector<Acc> Zeros; // a row outside the volume
  bool Avx2 = cpuHasAvx2();
};

/// Per-slice view handed to the consumer of the moments: everything needed to turn the
/// sums of slice z into statistics.
template <class T>
struct MomentSlice
{
  using Acc = typename MomentTraits<T>::Accumulator;
  std::int64_t z;         // output slice, volume coordinates
  const Acc* sum;         // region plane, x fastest
  const Acc* sumSquares;  //
  double shift;           // add to sum / count to get the mean
  std::int64_t countZ;    // clipped window size along z
  double roundingVariance; // what rounding can fake on a flat box (MomentScale)
};

/// Streams the moment planes of every region slice to consume(slice) on worker threads;
/// each thread takes a contiguous chunk of slices. Returns false when cancelled.
template <class T, class Consume>
bool streamMoments(const TypedVolume<T>& volume, const BoxGeometry& geometry, const MomentScale& scale,
  const Execution& execution, Consume&& consume)
{
  const auto shift = static_cast<typename MomentTraits<T>::Accumulator>(scale.shift);
  const int threads = resolveThreadCount(execution.threads);
  const std::int64_t nz = geometry.region.size[2];
  return parallelFor(nz, threads, threads, execution,
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress) {
      MomentPlanes<T> planes(volume, geometry, shift);
      for (std::int64_t k = begin; k < end; ++k)
      {
        const std::int64_t z = geometry.region.begin[2] + k;
        if (k == begin)
        {
          planes.startAt(z);
        }
        else
        {
          planes.advanceFrom(z - 1);
        }
        MomentSlice<T> slice{ z, planes.sum(), planes.sumSquares(), static_cast<double>(shift),
          clippedWindowCount(z, geometry.radius.z, geometry.dims[2]), scale.roundingVariance };
        consume(slice);
        if (!progress.advance())
        {
          return;
        }
      }
    });
}

/// Box minimum and maximum of every region voxel: planes of the slices the region reads,
/// the region's own slices starting at `offset` (x fastest, region-sized planes).
template <class T>
struct BoxExtrema
{
  std::vector<T> minimumPlanes;
  std::vector<T> maximumPlanes;
  std::int64_t offset = 0;

  T minimum(std::int64_t regionIndex) const { return this->minimumPlanes[this->offset + regionIndex]; }
  T maximum(std::int64_t regionIndex) const { return this->maximumPlanes[this->offset + regionIndex]; }
};

/// Three van Herk passes: x then y within each slice the region reads (into planes of
/// region width), then z along each region row, written back in place. Progress: slices,
/// then rows.
template <class T>
bool computeBoxExtrema(const TypedVolume<T>& volume, const BoxGeometry& geometry,
  const Execution& execution, BoxExtrema<T>& result)
{
  const Region& region = geometry.region;
  const std::int64_t nx = region.size[0];
  const std::int64_t plane = geometry.planeSize();
  const std::int64_t slices = geometry.zs.size();
  std::vector<T>& planeMin = result.minimumPlanes;
  std::vector<T>& planeMax = result.maximumPlanes;
  planeMin.resize(static_cast<std::size_t>(slices * plane));
  planeMax.resize(static_cast<std::size_t>(slices * plane));
  result.offset = (region.begin[2] - geometry.zs.lo) * plane;
  const int threads = resolveThreadCount(execution.threads);
  // Progress: the slices of the x/y passes, then the rows of the z pass.
  const std::int64_t work = slices + region.size[1];
  const bool planesDone = parallelFor(slices, threads, threads, stageExecution(execution, 0.0, double(slices) / work),
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress) {
      const std::int64_t span = geometry.xs.size();
      const std::int64_t rows = geometry.ys.size();
      std::vector<T> row(static_cast<std::size_t>(span));
      std::vector<T> xMin(static_cast<std::size_t>(rows * nx));
      std::vector<T> xMax(static_cast<std::size_t>(rows * nx));
      ExtremumScratch<T> scratch;
      for (std::int64_t s = begin; s < end && !progress.stopped(); ++s)
      {
        const std::int64_t z = geometry.zs.lo + s;
        for (std::int64_t j = 0; j < rows; ++j)
        {
          const T* src = volume.row(geometry.ys.lo + j, z) + geometry.xs.lo * volume.stride;
          for (std::int64_t i = 0; i < span; ++i)
          {
            row[i] = src[i * volume.stride];
          }
          const std::int64_t x0 = region.begin[0] - geometry.xs.lo;
          slidingMinMax(row.data(), row.data(), span, 1, geometry.radius.x, x0, nx, &xMin[j * nx],
            &xMax[j * nx], scratch);
        }
        // y pass: whole rows are the lanes.
        const std::int64_t y0 = region.begin[1] - geometry.ys.lo;
        slidingMinMax(xMin.data(), xMax.data(), rows, nx, geometry.radius.y, y0, region.size[1],
          &planeMin[s * plane], &planeMax[s * plane], scratch);
        progress.advance();
      }
    });
  if (!planesDone)
  {
    return false;
  }

  return parallelFor(region.size[1], threads, threads, stageExecution(execution, double(slices) / work, 1.0),
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress) {
      std::vector<T> lanesMin(static_cast<std::size_t>(slices * nx));
      std::vector<T> lanesMax(static_cast<std::size_t>(slices * nx));
      std::vector<T> outMin(static_cast<std::size_t>(region.size[2] * nx));
      std::vector<T> outMax(static_cast<std::size_t>(region.size[2] * nx));
      ExtremumScratch<T> scratch;
      const std::int64_t z0 = region.begin[2] - geometry.zs.lo;
      for (std::int64_t y = begin; y < end && !progress.stopped(); ++y)
      {
        // z pass: row y of every slice, gathered, is a sequence of lane vectors.
        for (std::int64_t s = 0; s < slices; ++s)
        {
          const std::int64_t from = s * plane + y * nx;
          std::copy(&planeMin[from], &planeMin[from] + nx, &lanesMin[s * nx]);
          std::copy(&planeMax[from], &planeMax[from] + nx, &lanesMax[s * nx]);
        }
        slidingMinMax(lanesMin.data(), lanesMax.data(), slices, nx, geometry.radius.z, z0,
          region.size[2], outMin.data(), outMax.data(), scratch);
        // In place: this row of every slice was gathered above.
        for (std::int64_t k = 0; k < region.size[2]; ++k)
        {
          const std::int64_t to = result.offset + k * plane + y * nx;
          std::copy(&outMin[k * nx], &outMin[k * nx] + nx, &planeMin[to]);
          std::copy(&outMax[k * nx], &outMax[k * nx] + nx, &planeMax[to]);
        }
        progress.advance();
      }
    });
}

} // namespace detail
} // namespace vao

namespace vao
{
namespace detail
{

/// One row of the region with the statistics of its voxels' neighbourhoods, as arrays
/// (x fastest), handed to a consumer: a row at a time lets the estimators run on vectors.
struct NeighbourhoodRow
{
  std::int64_t index = 0; // of the row's first voxel in the region, x fastest
  std::int64_t size = 0;  // voxels in the row
  const double* value = nullptr;    // the voxels' own values
  const double* count = nullptr;    // voxels in each clipped box
  const double* mean = nullptr;
  const double* variance = nullptr; // population variance, clamped at 0
  const double* minimum = nullptr;  // null unless the extrema were asked for
  const double* maximum = nullptr;
  double roundingVariance = 0.0;    // as NeighbourhoodStats::roundingVariance

  NeighbourhoodStats stats(std::int64_t i) const
  {
    return { this->mean[i], this->variance[i], this->minimum ? this->minimum[i] : 0.0,
      this->maximum ? this->maximum[i] : 0.0, this->roundingVariance };
  }
};

/// forEachNeighbourhoodRow on one band (band.region, a slab of rows of `whole`): voxel
/// indices are those of the whole region.
template <class T, class Visit>
bool visitBand(const TypedVolume<T>& volume, const BoxGeometry& band, const Region& whole,
  const MomentScale& scale, bool withExtrema, const Execution& execution, Visit&& visit)
{
  const Region& region = band.region;
  BoxExtrema<T> extrema;
  const double split = withExtrema ? 0.5 : 0.0;
  if (withExtrema && !computeBoxExtrema(volume, band, stageExecution(execution, 0.0, split), extrema))
  {
    return false;
  }
  const auto countX = band.windowCounts(0);
  const auto countY = band.windowCounts(1);
  const std::int64_t nx = region.size[0], ny = region.size[1];
  const std::int64_t wholePlane = whole.size[0] * whole.size[1];
  const std::int64_t firstRow = region.begin[1] - whole.begin[1];
  return streamMoments(volume, band, scale, stageExecution(execution, split, 1.0),
    [&](const MomentSlice<T>& slice) {
      const std::int64_t bandBase = (slice.z - region.begin[2]) * nx * ny;
      const std::int64_t base = (slice.z - whole.begin[2]) * wholePlane + firstRow * nx;
      const auto n = static_cast<std::size_t>(nx);
      std::vector<double> value(n), count(n), mean(n), variance(n), minimum, maximum;
      if (withExtrema)
      {
        minimum.resize(n);
        maximum.resize(n);
      }
      NeighbourhoodRow out;
      out.size = nx;
      out.value = value.data();
      out.count = count.data();
      out.mean = mean.data();
      out.variance = variance.data();
      out.minimum = withExtrema ? minimum.data() : nullptr;
      out.maximum = withExtrema ? maximum.data() : nullptr;
      out.roundingVariance = slice.roundingVariance;
      for (std::int64_t j = 0; j < ny; ++j)
      {
        const T* row = volume.row(region.begin[1] + j, slice.z) + region.begin[0] * volume.stride;
        const std::int64_t countYZ = countY[j] * slice.countZ;
        for (std::int64_t i = 0; i < nx; ++i)
        {
          const std::int64_t p = j * nx + i;
          const std::int64_t c = countX[i] * countYZ;
          value[i] = static_cast<double>(row[i * volume.stride]);
          count[i] = static_cast<double>(c);
          meanVarianceFromSums(slice.sum[p], slice.sumSquares[p], c, slice.shift, mean[i], variance[i]);
        }
        if (withExtrema)
        {
          for (std::int64_t i = 0; i < nx; ++i)
          {
            minimum[i] = static_cast<double>(extrema.minimum(bandBase + j * nx + i));
            maximum[i] = static_cast<double>(extrema.maximum(bandBase + j * nx + i));
          }
        }
        out.index = base + j * nx;
        visit(static_cast<const NeighbourhoodRow&>(out));
      }
    });
}

/// Rows of region per band when the extrema are needed: a band's extrema planes hold
/// 2 x (slices read) x rows x width values, so bands of 1/16 of the volume's rows keep
/// them at 1/8 of the input's size (working memory stays under 25% of the input),
/// at the price of re-reading R rows above and below each band in the x passes; bands
/// of at least 2R + 1 rows keep that price under 2x.
inline std::int64_t extremaBandRows(const BoxGeometry& geometry)
{
  return std::max<std::int64_t>({ 8, geometry.dims[1] / 16, 2 * std::int64_t(geometry.radius.y) + 1 });
}

/// The separable statistics of every region voxel, handed to visit(NeighbourhoodRow) row
/// by row, slice by slice on worker threads: the streamed moments, after the extrema passes when
/// withExtrema. With the extrema the region goes band by band of rows (extremaBandRows),
/// each band's extrema first, then its moments. Returns false when cancelled.
template <class T, class Visit>
bool forEachNeighbourhoodRow(const TypedVolume<T>& volume, const BoxGeometry& geometry,
  const MomentScale& scale, bool withExtrema, const Execution& execution, Visit&& visit)
{
  const Region& region = geometry.region;
  const std::int64_t ny = region.size[1];
  const std::int64_t bandRows = withExtrema ? std::min(ny, extremaBandRows(geometry)) : ny;
  const std::int64_t bands = (ny + bandRows - 1) / bandRows;
  for (std::int64_t b = 0; b < bands; ++b)
  {
    Region band = region;
    band.begin[1] = region.begin[1] + b * bandRows;
    band.size[1] = std::min(bandRows, ny - b * bandRows);
    const Execution stage = stageExecution(execution, double(b) / bands, double(b + 1) / bands);
    if (!visitBand(volume, BoxGeometry(geometry.dims, band, geometry.radius), region, scale, withExtrema, stage, visit))
    {
      return false;
    }
  }
  return true;
}

} // namespace detail
} // namespace vao
