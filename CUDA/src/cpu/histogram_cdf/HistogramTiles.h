// How Histogram CDF on the CPU (HistogramChannels.cxx) cuts the region into tiles, and the
// lane widths a tile's state takes.
#pragma once

#include "vao/AmbientOcclusion.h"

#include <cstdint>
#include <limits>

namespace vao
{
namespace detail
{

constexpr int kLaneMultiple = 16;

/// Lanes of a bin count: a multiple of kLaneMultiple (the AVX2 width of 16-bit lanes).
inline int laneCount(int bins)
{
  return (bins + kLaneMultiple - 1) / kLaneMultiple * kLaneMultiple;
}

/// Whether the window's counts (at most 2 Rz + 1 per pixel) fit 8-bit lanes, with the
/// difference of two counts in their signed range (SlideRows).
inline bool narrowWindow(const Radius& r)
{
  return 2 * std::int64_t(r.z) + 1 <= std::numeric_limits<std::int8_t>::max();
}

/// Slices whose bins a tile keeps: those of a z window and its next entering slice.
inline std::int64_t ringSlices(const Radius& r)
{
  return 2 * std::int64_t(r.z) + 2;
}

/// Bytes of a voxel's bin in the ring: 8 bits for the default 64 bins (the loops of a known
/// lane count), else 16.
inline int binBytes(int lanes)
{
  return lanes == 64 ? 1 : 2;
}

/// How the region is cut: tiles of sideX x sideY output columns (tilesX x tilesY of them,
/// balanced), each cut into zParts ranges of slices; a unit of work is one tile's z-range.
/// A tile grown by the radius, within the volume, has at most spanX x spanY pixels.
struct TilePlan
{
  std::int64_t sideX = 0, sideY = 0, tilesX = 0, tilesY = 0, zParts = 0;
  std::int64_t spanX = 0, spanY = 0;
  std::int64_t units() const { return tilesX * tilesY * zParts; }
};

/// The plan whose slowest thread has the least work. A unit's work is its outputs plus its
/// window's pixels over its slices and the 2 Rz slices that start the window, both grown
/// by the border it recounts; the units go to the threads as they free up, so the slowest
/// does ceil(units / threads) of the largest. Tiles are at most 256 columns a side (larger
/// ones save little border and leave the processor's caches), and the workers' states
/// together take at most a fifth of the input's bytes or 16 MiB, whichever is more (with
/// the value histogram and the row buffers, the filter's extra memory stays within its 25%
/// bar on volumes above 80 MiB; smaller ones get whole-slice tiles, which recount no
/// border).
TilePlan planTiles(const Index3& size, const Index3& dims, std::int64_t inputBytes, const Radius& r,
  int lanes, int laneBytes, int threads);

} // namespace detail
} // namespace vao
