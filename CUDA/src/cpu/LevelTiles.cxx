// The tiled levels of a SurfacePyramid (LevelTiles.h): marking, and building the tiles
// marked with the blur of the whole levels (PyramidBlur.h).
#include "vao/Storage.h"

#include "LevelTiles.h"
#include "PyramidBlur.h"

#include <algorithm>
#include <limits>
#include <new>
#include <vector>

namespace vao
{
namespace detail
{
using namespace pyramid;

LevelTiles::LevelTiles(const VolumeView& volume, const MomentLevel& geometry, int level, int firstStep, double shift)
  : Volume(volume)
  , Level(level)
  , FirstStep(firstStep)
  , Shift(shift)
{
  this->setGeometry(geometry);
  for (int a = 0; a < 3; ++a)
  {
    this->Tiles[a] = (geometry.dims[a] + kTileSide - 1) / kTileSide;
  }
  const std::int64_t count = this->tileCount();
  this->State.reset(new std::atomic<std::uint8_t>[static_cast<std::size_t>(count)]);
  for (std::int64_t t = 0; t < count; ++t)
  {
    this->State[t].store(0, std::memory_order_relaxed);
  }
  this->PoolBytes = static_cast<std::size_t>(count) * 2 * kTileVoxels * sizeof(float);
  this->Pool = static_cast<float*>(allocateSparseStorage(this->PoolBytes));
  if (!this->Pool)
  {
    throw std::bad_alloc();
  }
  this->prepareGrid();
  this->forgetMarks();
}

LevelTiles::~LevelTiles()
{
  freeSparseStorage(this->Pool, this->PoolBytes);
}

void LevelTiles::setGeometry(const MomentLevel& geometry)
{
  this->Geometry.dims = geometry.dims;
  this->Geometry.origin = geometry.origin;
  this->Geometry.spacing = geometry.spacing;
  this->Geometry.kernelRadius = geometry.kernelRadius;
  this->Geometry.wholeBounds = geometry.wholeBounds;
  this->Geometry.roundingVariance = geometry.roundingVariance;
}

void LevelTiles::prepareGrid()
{
  LevelGrid& g = this->Grid;
  g = LevelGrid(this->Geometry); // the geometry; the pointers and strides are the tiles'
  g.mean = this->Pool; // (mean, variance) pairs: every index and stride counts floats
  g.variance = this->Pool + 1;
  g.tiled = true;
  g.stride[0] = 2;
  g.stride[1] = 2 * kTileSide;
  g.stride[2] = 2 * kTileSide * kTileSide;
  g.tileStride[0] = 2 * kTileVoxels;
  g.tileStride[1] = g.tileStride[0] * this->Tiles[0];
  g.tileStride[2] = g.tileStride[1] * this->Tiles[1];
  g.narrowIndices = this->PoolBytes / sizeof(float) <= static_cast<std::size_t>(std::numeric_limits<std::int32_t>::max());
  g.pairedRows = false;
}

void LevelTiles::markAround(double x, double y, double z)
{
  // The cell's lower corner as trilinearSample finds it, from the same grid numbers.
  const LevelGrid& g = this->Grid;
  const double p[3] = { x, y, z };
  std::int64_t lo[3], hi[3];
  for (int a = 0; a < 3; ++a)
  {
    const double u = std::min(std::max((p[a] - g.origin[a]) * g.inverseSpacing[a], 0.0), g.maxIndex[a]);
    const std::int64_t lower = static_cast<std::int64_t>(u);
    lo[a] = lower >> kTileShift;
    hi[a] = std::min<std::int64_t>(this->Geometry.dims[a] - 1, lower + 1) >> kTileShift;
  }
  std::int64_t lowest = this->LowestMarked.load(std::memory_order_relaxed);
  while (lo[2] < lowest && !this->LowestMarked.compare_exchange_weak(lowest, lo[2], std::memory_order_relaxed))
  {
  }
  for (std::int64_t tz = lo[2]; tz <= hi[2]; ++tz)
    for (std::int64_t ty = lo[1]; ty <= hi[1]; ++ty)
      for (std::int64_t tx = lo[0]; tx <= hi[0]; ++tx)
      {
        std::atomic<std::uint8_t>& state = this->State[(tz * this->Tiles[1] + ty) * this->Tiles[0] + tx];
        if (state.load(std::memory_order_relaxed) == 0)
          state.store(1, std::memory_order_relaxed);
      }
}

std::int64_t LevelTiles::layerOf(double z) const
{
  const LevelGrid& g = this->Grid;
  const double u = std::min(std::max((z - g.origin[2]) * g.inverseSpacing[2], 0.0), g.maxIndex[2]);
  return static_cast<std::int64_t>(u) >> kTileShift;
}

void LevelTiles::forgetMarks()
{
  this->LowestMarked.store(this->Tiles[2], std::memory_order_relaxed);
}

void LevelTiles::releaseLayer(std::int64_t layer)
{
  const std::int64_t perLayer = this->Tiles[0] * this->Tiles[1];
  std::int64_t released = 0;
  for (std::int64_t t = layer * perLayer; t < (layer + 1) * perLayer; ++t)
  {
    if (this->State[t].load(std::memory_order_relaxed) == 2)
    {
      this->State[t].store(0, std::memory_order_relaxed);
      ++released;
    }
  }
  if (released > 0)
  {
    releaseSparseStorage(this->Pool + layer * perLayer * 2 * kTileVoxels,
      static_cast<std::size_t>(perLayer) * PyramidTiles::kTileBytes);
    this->Built.fetch_sub(released, std::memory_order_relaxed);
  }
}

bool LevelTiles::buildMarked(const Execution& execution)
{
  // Runs of marked tiles along x (consecutive in memory): one window and one page
  // preparation per run.
  std::vector<TileRun> runs;
  for (std::int64_t t = 0; t < this->tileCount(); ++t)
  {
    if (this->State[t].load(std::memory_order_relaxed) != 1)
      continue;
    if (!runs.empty() && runs.back().first + runs.back().count == t && t % this->Tiles[0] != 0)
      ++runs.back().count;
    else
      runs.push_back({ t, 1 });
  }
  if (runs.empty())
  {
    return true;
  }
  return dispatchScalarType(this->Volume.type, [&](auto tag) { return this->build<decltype(tag)>(runs, execution); });
}

namespace
{

/// The voxels [lo, lo + size) of a level kept as a block (means then variances, x
/// fastest): level 1's tiles read level 0 there.
struct BlockVoxels
{
  const float* mean = nullptr;
  std::int64_t lo[3] = { 0, 0, 0 };
  std::int64_t size[3] = { 0, 0, 0 };

  std::pair<const float*, const float*> operator()(std::int64_t x, std::int64_t y, std::int64_t z) const
  {
    const float* voxel = mean + ((z - lo[2]) * size[1] + (y - lo[1])) * size[0] + (x - lo[0]);
    return { voxel, voxel + size[0] * size[1] * size[2] };
  }
};

/// Output voxels [lo, hi) of a blur (plan) into `block` (means then variances, rows of
/// hi - lo x voxels), with the SliceBlur of the source narrowed to them.
template <class Source>
void blurBlock(SliceBlur<Source>& blur, const std::int64_t* lo, const std::int64_t* hi, float* block)
{
  const std::int64_t nx = hi[0] - lo[0], ny = hi[1] - lo[1];
  const std::int64_t plane = nx * ny * (hi[2] - lo[2]);
  blur.setWindow({ lo[0], hi[0], lo[1], hi[1] });
  for (std::int64_t zo = lo[2]; zo < hi[2]; ++zo)
  {
    blur.slice(zo, [&](std::int64_t yo) {
      float* mean = block + ((zo - lo[2]) * ny + (yo - lo[1])) * nx;
      return std::make_pair(mean, mean + plane);
    });
  }
}

} // namespace

template <class T>
bool LevelTiles::build(const std::vector<TileRun>& runs, const Execution& execution)
{
  const RawSource<T> source{ TypedVolume<T>(this->Volume), this->Shift };
  const BlurPlan plan0(this->Volume.dims, this->FirstStep, this->Shift);
  const BlurPlan plan1(plan0.out, 2, this->Shift);
  const int threads = resolveThreadCount(execution.threads);
  const auto count = static_cast<std::int64_t>(runs.size());
  const int chunks = static_cast<int>(std::min<std::int64_t>(count, std::max(1, threads) * 8));
  const Index3& n = this->Geometry.dims;
  return parallelFor(count, chunks, threads, execution, [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress) {
    SliceBlur<RawSource<T>> blur0(source, plan0);
    StoredSource<BlockVoxels> base{ {}, plan0.out, this->Shift }; // level 1: the block of level 0 its taps read
    SliceBlur<StoredSource<BlockVoxels>> blur1(base, plan1);
    std::vector<float> block, baseBlock; // a run's voxels before they go to their tiles
    for (std::int64_t r = begin; r < end; ++r)
    {
      const TileRun& run = runs[static_cast<std::size_t>(r)];
      float* first = this->Pool + run.first * 2 * kTileVoxels;
      // The run's pages in one call, not a fault each: on some virtual machines a fault
      // costs 17 us, more than blurring the tile.
      if (!prepareSparseStorage(first, static_cast<std::size_t>(run.count) * 2 * kTileVoxels * sizeof(float)))
        throw std::bad_alloc();
      const std::int64_t c[3] = { run.first % this->Tiles[0], (run.first / this->Tiles[0]) % this->Tiles[1],
        run.first / (this->Tiles[0] * this->Tiles[1]) };
      std::int64_t lo[3], hi[3];
      for (int a = 0; a < 3; ++a)
      {
        lo[a] = c[a] * kTileSide;
        hi[a] = std::min(lo[a] + kTileSide * (a == 0 ? run.count : 1), n[a]);
      }
      const std::int64_t width = hi[0] - lo[0], rows = (hi[1] - lo[1]) * (hi[2] - lo[2]);
      block.resize(static_cast<std::size_t>(2 * width * rows));
      if (this->Level == 0)
      {
        blurBlock(blur0, lo, hi, block.data());
      }
      else
      {
        // Level 0 where level 1's taps reach (clamped to the level, as the blur clamps).
        BlockVoxels& block0 = base.at;
        std::int64_t baseHi[3];
        for (int a = 0; a < 3; ++a)
        {
          block0.lo[a] = std::max<std::int64_t>(0, 2 * lo[a] - kHalf);
          baseHi[a] = std::min<std::int64_t>(plan0.out[a], 2 * (hi[a] - 1) + kHalf + 1);
          block0.size[a] = baseHi[a] - block0.lo[a];
        }
        baseBlock.resize(static_cast<std::size_t>(2 * block0.size[0] * block0.size[1] * block0.size[2]));
        blurBlock(blur0, block0.lo, baseHi, baseBlock.data());
        block0.mean = baseBlock.data();
        blurBlock(blur1, lo, hi, block.data());
      }
      // Rows of the block to rows of its tiles (a partial tile's other voxels are never read).
      const std::int64_t plane = width * rows;
      for (std::int64_t k = 0; k < run.count; ++k)
      {
        float* tile = first + k * 2 * kTileVoxels;
        const std::int64_t x0 = k * kTileSide, x1 = std::min(width, x0 + kTileSide);
        for (std::int64_t z = 0; z < hi[2] - lo[2]; ++z)
          for (std::int64_t y = 0; y < hi[1] - lo[1]; ++y)
            for (std::int64_t x = x0; x < x1; ++x)
            {
              const std::int64_t from = (z * (hi[1] - lo[1]) + y) * width + x;
              const std::int64_t to = (z * kTileSide + y) * kTileSide + (x - x0);
              tile[2 * to] = block[from];
              tile[2 * to + 1] = block[plane + from];
            }
        this->State[run.first + k].store(2, std::memory_order_release);
      }
      this->Built.fetch_add(run.count, std::memory_order_relaxed);
      this->Made.fetch_add(run.count, std::memory_order_relaxed);
      if (!progress.advance())
      {
        return;
      }
    }
  });
}


bool PyramidTiles::buildMarked(const Execution& execution)
{
  for (int l = 0; l < this->count(); ++l)
  {
    const double width = 1.0 / this->count();
    if (!this->levels[l]->buildMarked(stageExecution(execution, l * width, (l + 1) * width)))
      return false;
  }
  return true;
}

std::size_t PyramidTiles::builtBytes() const
{
  std::size_t bytes = 0;
  for (const auto& level : this->levels)
    bytes += static_cast<std::size_t>(level->builtTiles()) * kTileBytes;
  return bytes;
}

void PyramidTiles::forgetMarks()
{
  for (const auto& level : this->levels)
    level->forgetMarks();
}

void PyramidTiles::releaseBelowMarks()
{
  // Level l goes while its tiles and the coarser ones' take more than keptBytes: a finer
  // level's tiles are released to keep the coarser ones, never the other way.
  for (std::size_t l = 0; l < this->levels.size(); ++l)
  {
    auto heldFrom = [&] {
      std::size_t bytes = 0;
      for (std::size_t m = l; m < this->levels.size(); ++m)
        bytes += static_cast<std::size_t>(this->levels[m]->builtTiles()) * kTileBytes;
      return bytes;
    };
    LevelTiles& level = *this->levels[l];
    const std::int64_t below = std::min(level.lowestMarked(), level.layerCount());
    for (std::int64_t layer = 0; layer < below && heldFrom() > this->keptBytes; ++layer)
      level.releaseLayer(layer);
  }
}

} // namespace detail
} // namespace vao
