// The box minimum and maximum of every region voxel, for CDF Reconstruction and the
// statistics: not invertible, so not running sums (MomentPlanes.h) but three van Herk
// passes, y per slice and z per row (computeBoxExtrema), then x per slice as its rows are
// consumed (SliceExtrema, BoxEngine.h's visitBand).
#pragma once

#include "cpu/box_statistics/MomentPlanes.h"
#include "cpu/box_statistics/RowTranspose.h"
#include "cpu/box_statistics/SlidingExtremum.h"
#include "vao/Storage.h"

#include <algorithm>
#include <cstdint>
#include <vector>

namespace vao
{
namespace detail
{

/// Box minimum and maximum of every region voxel, in two steps. computeBoxExtrema runs
/// the y pass on every slice the region reads, straight from the volume, and then the z
/// pass along each row, into planes of the region's rows by the x span its boxes read;
/// SliceExtrema runs the x pass of one region slice as its rows are consumed. The x pass
/// comes last so that it takes the region's rows alone: a band of rows (forEachNeighbourhoodRow)
/// reads R rows above and below it, which an x pass first would also take. Minima and
/// maxima are exact in any order of the passes.
template <class T>
struct BoxExtrema
{
  StorageArray<T> minimumPlanes; // uninitialised: the y pass writes every plane whole
  StorageArray<T> maximumPlanes;
  std::int64_t offset = 0; // where the region's first slice starts
  std::int64_t width = 0;  // values a plane row holds: the x span the boxes read
  std::int64_t rows = 0;   // rows a plane holds: the region's

  /// Row j of region slice k, after the y and z passes.
  const T* minimumRow(std::int64_t k, std::int64_t j) const
  {
    return this->minimumPlanes.data() + this->offset + (k * this->rows + j) * this->width;
  }
  const T* maximumRow(std::int64_t k, std::int64_t j) const
  {
    return this->maximumPlanes.data() + this->offset + (k * this->rows + j) * this->width;
  }
};

/// Rows of a slice whose x passes run together (one AVX2 vector of 16-bit values).
constexpr std::int64_t kExtremumRows = 16;

/// The y pass of every slice the region reads, then the z pass along each region row,
/// written back in place (BoxExtrema). Progress: slices, then rows.
template <class T>
bool computeBoxExtrema(const TypedVolume<T>& volume, const BoxGeometry& geometry,
  const Execution& execution, BoxExtrema<T>& result)
{
  const Region& region = geometry.region;
  const std::int64_t span = geometry.xs.size();
  const std::int64_t rows = region.size[1];
  const std::int64_t plane = span * rows;
  const std::int64_t slices = geometry.zs.size();
  StorageArray<T>& planeMin = result.minimumPlanes;
  StorageArray<T>& planeMax = result.maximumPlanes;
  planeMin.resize(static_cast<std::size_t>(slices * plane));
  planeMax.resize(static_cast<std::size_t>(slices * plane));
  result.offset = (region.begin[2] - geometry.zs.lo) * plane;
  result.width = span;
  result.rows = rows;
  const int threads = resolveThreadCount(execution.threads);
  // Progress: the slices of the y pass, then the rows of the z pass.
  const std::int64_t work = slices + rows;
  const bool planesDone = parallelFor(slices, threads, threads,
    stageExecution(execution, 0.0, double(slices) / work),
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress)
    {
      const std::int64_t read = geometry.ys.size();
      // Interleaved voxels (one component of several) are gathered first: the pass takes
      // each row's span as contiguous lanes.
      std::vector<T> gathered(volume.stride == 1 ? 0 : static_cast<std::size_t>(read * span));
      ExtremumScratch<T> scratch;
      for (std::int64_t s = begin; s < end && !progress.stopped(); ++s)
      {
        const std::int64_t z = geometry.zs.lo + s;
        const T* first = volume.row(geometry.ys.lo, z) + geometry.xs.lo * volume.stride;
        std::int64_t rowStride = volume.dims[0]; // values from one row's first to the next's
        if (volume.stride != 1)
        {
          for (std::int64_t j = 0; j < read; ++j)
          {
            const T* row = volume.row(geometry.ys.lo + j, z) + geometry.xs.lo * volume.stride;
            for (std::int64_t i = 0; i < span; ++i)
              gathered[static_cast<std::size_t>(j * span + i)] = row[i * volume.stride];
          }
          first = gathered.data();
          rowStride = span;
        }
        // y pass: the rows are the sequence, their x spans the lanes.
        slidingMinMax(first, first, read, span, geometry.radius.y, region.begin[1] - geometry.ys.lo,
          rows, &planeMin[s * plane], &planeMax[s * plane], scratch, rowStride);
        progress.advance();
      }
    });
  if (!planesDone)
  {
    return false;
  }

  return parallelFor(rows, threads, threads, stageExecution(execution, double(slices) / work, 1.0),
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress)
    {
      ExtremumScratch<T> scratch;
      const std::int64_t z0 = region.begin[2] - geometry.zs.lo;
      for (std::int64_t y = begin; y < end && !progress.stopped(); ++y)
      {
        // z pass: row y of every slice is a sequence of lane vectors, a plane apart; the
        // results go back in place (the pass reads all of its input first).
        T* rowMin = &planeMin[y * span];
        T* rowMax = &planeMax[y * span];
        slidingMinMax(rowMin, rowMax, slices, span, geometry.radius.z, z0, region.size[2],
          rowMin + result.offset, rowMax + result.offset, scratch, plane, plane);
        progress.advance();
      }
    });
}

/// The x pass of one region slice (BoxExtrema's y and z passes done): the box minima and
/// maxima of its voxels, a row of the region's width per region row. Each worker of
/// visitBand keeps one for the slices it consumes, so its buffers are made once.
template <class T>
class SliceExtrema
{
public:
  const T* minima(std::int64_t j) const { return this->Minima.data() + j * this->Width; }
  const T* maxima(std::int64_t j) const { return this->Maxima.data() + j * this->Width; }

  /// Region slice k: kExtremumRows rows at once, transposed so that the rows are the
  /// lanes and the recurrence runs along x on vectors.
  void compute(const BoxExtrema<T>& extrema, const BoxGeometry& geometry, std::int64_t k)
  {
    const Region& region = geometry.region;
    const std::int64_t nx = region.size[0], span = extrema.width;
    this->Width = nx;
    this->Minima.resize(static_cast<std::size_t>(extrema.rows * nx));
    this->Maxima.resize(this->Minima.size());
    this->LanesMin.resize(static_cast<std::size_t>(span * kExtremumRows));
    this->LanesMax.resize(this->LanesMin.size());
    this->OutMin.resize(static_cast<std::size_t>(nx * kExtremumRows));
    this->OutMax.resize(this->OutMin.size());
    // A last group of fewer rows runs as a whole one where the transposes take blocks of
    // 16 rows (else they and the pass would go value by value): its spare lanes repeat
    // the last row and their results go to a row that is not kept.
    const bool padded = transposesInBlocks<T>();
    this->Spare.resize(static_cast<std::size_t>(padded ? 2 * nx : 0));
    const std::int64_t x0 = region.begin[0] - geometry.xs.lo;
    for (std::int64_t j0 = 0; j0 < extrema.rows; j0 += kExtremumRows)
    {
      const std::int64_t m = std::min(kExtremumRows, extrema.rows - j0);
      const std::int64_t lanes = padded ? kExtremumRows : m;
      const T* inMin[kExtremumRows];
      const T* inMax[kExtremumRows];
      T* minRows[kExtremumRows];
      T* maxRows[kExtremumRows];
      for (std::int64_t r = 0; r < lanes; ++r)
      {
        const std::int64_t j = j0 + std::min(r, m - 1);
        inMin[r] = extrema.minimumRow(k, j);
        inMax[r] = extrema.maximumRow(k, j);
        minRows[r] = r < m ? &this->Minima[static_cast<std::size_t>(j * nx)] : this->Spare.data();
        maxRows[r] =
          r < m ? &this->Maxima[static_cast<std::size_t>(j * nx)] : this->Spare.data() + nx;
      }
      rowsToLanes(inMin, lanes, 1, span, this->LanesMin.data());
      rowsToLanes(inMax, lanes, 1, span, this->LanesMax.data());
      slidingMinMax(this->LanesMin.data(), this->LanesMax.data(), span, lanes, geometry.radius.x,
        x0, nx, this->OutMin.data(), this->OutMax.data(), this->Scratch);
      lanesToRows(this->OutMin.data(), lanes, nx, minRows);
      lanesToRows(this->OutMax.data(), lanes, nx, maxRows);
    }
  }

private:
  std::int64_t Width = 0;
  std::vector<T> Minima, Maxima;                     // rows of the region's width
  std::vector<T> LanesMin, LanesMax, OutMin, OutMax; // the transposed rows, in and out
  std::vector<T> Spare;                              // results of padding lanes, not kept
  ExtremumScratch<T> Scratch;
};

} // namespace detail
} // namespace vao
