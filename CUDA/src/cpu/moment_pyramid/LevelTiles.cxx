// The tiled levels of a SurfacePyramid (LevelTiles.h): marking, and building the tiles
// marked with the blur of the whole levels (PyramidBlur.h).
#include "cpu/common/SparseStorage.h"

#include "cpu/moment_pyramid/LevelTiles.h"
#include "cpu/moment_pyramid/PyramidBlur.h"

#include <algorithm>
#include <limits>
#include <new>
#include <vector>

namespace vao
{
namespace detail
{
using namespace pyramid;

LevelTiles::LevelTiles(TilePool& pool, const VolumeView& volume, const MomentLevel& geometry,
  int level, int firstStep, double shift)
  : Volume(volume)
  , Level(level)
  , FirstStep(firstStep)
  , Shift(shift)
  , Pool(pool)
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
    this->State[t].store(kAbsent, std::memory_order_relaxed);
  }
  this->Offsets.reset(new std::int32_t[static_cast<std::size_t>(count)]());
  this->prepareGrid();
  this->forgetMarks();
}

LevelTiles::~LevelTiles() = default;

std::int64_t LevelTiles::tilesOf(const Index3& dims)
{
  std::int64_t count = 1;
  for (int a = 0; a < 3; ++a)
    count *= (dims[a] + kTileSide - 1) / kTileSide;
  return count;
}

TilePool::TilePool(std::int64_t tiles)
  : Capacity(static_cast<std::int32_t>(
      std::min<std::int64_t>(tiles, std::numeric_limits<std::int32_t>::max() / kTileFloats)))
{
  this->Bytes = static_cast<std::size_t>(this->Capacity) * PyramidTiles::kTileBytes;
  this->Pool = static_cast<float*>(allocateSparseStorage(this->Bytes));
  if (!this->Pool)
  {
    throw std::bad_alloc();
  }
}

TilePool::~TilePool()
{
  freeSparseStorage(this->Pool, this->Bytes);
}

std::int32_t TilePool::take()
{
  if (!this->Free.empty())
  {
    const std::int32_t offset = this->Free.back();
    this->Free.pop_back();
    return offset;
  }
  if (this->Used == this->Capacity)
    throw std::bad_alloc();
  return static_cast<std::int32_t>(this->Used++ * kTileFloats);
}

void TilePool::prepare()
{
  if (this->Used == this->Prepared)
    return;
  constexpr std::size_t kPage = 4096;
  const std::size_t from =
    static_cast<std::size_t>(this->Prepared) * PyramidTiles::kTileBytes / kPage * kPage;
  const std::size_t to = std::min(this->Bytes, (this->bytes() + kPage - 1) / kPage * kPage);
  if (!prepareSparseStorage(reinterpret_cast<char*>(this->Pool) + from, to - from))
    throw std::bad_alloc();
  this->Prepared = this->Used;
}

std::size_t TilePool::bytes() const
{
  return static_cast<std::size_t>(this->Used) * PyramidTiles::kTileBytes;
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
  g.mean = this->Pool.data();    // (mean, variance) pairs: every index and stride counts floats
  g.variance = this->Pool.data() + 1;
  g.tiled = true;
  g.stride[0] = 2;
  g.stride[1] = 2 * kTileSpan;
  g.stride[2] = 2 * kTileSpan * kTileSpan;
  g.tileStride[0] = 1;
  g.tileStride[1] = this->Tiles[0];
  g.tileStride[2] = this->Tiles[0] * this->Tiles[1];
  g.tileOffsets = this->Offsets.get();
  // The gathers take tile indices and float offsets in 32 bits; the pool's capacity
  // bounds the offsets.
  g.narrowIndices = this->tileCount() <= std::numeric_limits<std::int32_t>::max();
  g.pairedRows = false;
}

void LevelTiles::forgetMarks()
{
  // Tiles in use lie in the layers marked (built ones were marked first).
  const std::int64_t perLayer = this->Tiles[0] * this->Tiles[1];
  for (std::int64_t t = this->lowestMarked() * perLayer; t < (this->highestMarked() + 1) * perLayer;
       ++t)
  {
    if (this->State[t].load(std::memory_order_relaxed) == kInUse)
      this->State[t].store(kBuilt, std::memory_order_relaxed);
  }
  this->LowestMarked.store(this->Tiles[2], std::memory_order_relaxed);
  this->HighestMarked.store(-1, std::memory_order_relaxed);
}

void LevelTiles::settle()
{
  for (std::int64_t t = 0; t < this->tileCount(); ++t)
  {
    const std::uint8_t state = this->State[t].load(std::memory_order_relaxed);
    if (state == kInUse)
      this->State[t].store(kBuilt, std::memory_order_relaxed);
    else if (state == kMarked || state == kSlotted)
    {
      if (state == kSlotted)
        this->Pool.give(this->Offsets[t]);
      this->Offsets[t] = 0;
      this->State[t].store(kAbsent, std::memory_order_relaxed);
    }
  }
  this->LowestMarked.store(this->Tiles[2], std::memory_order_relaxed);
  this->HighestMarked.store(-1, std::memory_order_relaxed);
}

void LevelTiles::releaseLayer(std::int64_t layer)
{
  const std::int64_t perLayer = this->Tiles[0] * this->Tiles[1];
  for (std::int64_t t = layer * perLayer; t < (layer + 1) * perLayer; ++t)
  {
    if (this->State[t].load(std::memory_order_relaxed) == kBuilt)
    {
      this->State[t].store(kAbsent, std::memory_order_relaxed);
      this->Pool.give(this->Offsets[t]);
      this->Offsets[t] = 0;
      this->Built.fetch_sub(1, std::memory_order_relaxed);
    }
  }
}

bool LevelTiles::buildMarked(const Execution& execution)
{
  // Runs of marked tiles along x: one blurred block per run. Each tile takes a free slot,
  // else the next one of the pool.
  std::vector<TileRun> runs;
  for (std::int64_t t = 0; t < this->tileCount(); ++t)
  {
    if (this->State[t].load(std::memory_order_relaxed) != kMarked)
      continue;
    if (!runs.empty() && runs.back().first + runs.back().count == t && t % this->Tiles[0] != 0)
      ++runs.back().count;
    else
      runs.push_back({ t, 1 });
    this->Offsets[t] = this->Pool.take();
    this->State[t].store(kSlotted, std::memory_order_relaxed);
  }
  if (runs.empty())
  {
    return true;
  }
  this->Pool.prepare();
  return dispatchScalarType(
    this->Volume.type, [&](auto tag) { return this->build<decltype(tag)>(runs, execution); });
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

  std::pair<const float*, const float*> operator()(
    std::int64_t x, std::int64_t y, std::int64_t z) const
  {
    const float* voxel = mean + ((z - lo[2]) * size[1] + (y - lo[1])) * size[0] + (x - lo[0]);
    return { voxel, voxel + size[0] * size[1] * size[2] };
  }
};

/// Output voxels [lo, hi) of a blur (plan) into `block` (means then variances, rows of
/// hi - lo x voxels), with the SliceBlur of the source narrowed to them.
template <class Source>
void blurBlock(
  SliceBlur<Source>& blur, const std::int64_t* lo, const std::int64_t* hi, float* block)
{
  const std::int64_t nx = hi[0] - lo[0], ny = hi[1] - lo[1];
  const std::int64_t plane = nx * ny * (hi[2] - lo[2]);
  blur.setWindow({ lo[0], hi[0], lo[1], hi[1] });
  for (std::int64_t zo = lo[2]; zo < hi[2]; ++zo)
  {
    blur.slice(zo,
      [&](std::int64_t yo)
      {
        float* mean = block + ((zo - lo[2]) * ny + (yo - lo[1])) * nx;
        return std::make_pair(mean, mean + plane);
      });
  }
}

/// The level's voxels that a run of `count` tiles along x from tile `first` holds: [lo, hi)
/// in voxels of a level of n, each tile's cells and the shared face past its last cell.
inline void runVoxels(std::int64_t first, std::int64_t count, const Index3& tiles, const Index3& n,
  std::int64_t* lo, std::int64_t* hi)
{
  const std::int64_t c[3] = { first % tiles[0], (first / tiles[0]) % tiles[1],
    first / (tiles[0] * tiles[1]) };
  for (int a = 0; a < 3; ++a)
  {
    lo[a] = c[a] * kTileSide;
    hi[a] = std::min(lo[a] + kTileSide * (a == 0 ? count : 1) + 1, n[a]);
  }
}

/// Level 1's voxels [lo, hi) into `block`, in two blurs: level 0 where level 1's taps reach
/// (clamped to level 0's dims, as the blur clamps) into `baseBlock`, which `block0` then
/// points blur1's source at, and level 1's blur of it: level 1 is the blur of level 0
/// (PyramidBuild.cxx builds each level from the one before), not of the volume.
template <class Blur0, class Blur1>
void blurFromLevel0(Blur0& blur0, Blur1& blur1, BlockVoxels& block0, const Index3& level0,
  const std::int64_t* lo, const std::int64_t* hi, std::vector<float>& baseBlock, float* block)
{
  std::int64_t baseHi[3];
  for (int a = 0; a < 3; ++a)
  {
    block0.lo[a] = std::max<std::int64_t>(0, 2 * lo[a] - kHalf);
    baseHi[a] = std::min<std::int64_t>(level0[a], 2 * (hi[a] - 1) + kHalf + 1);
    block0.size[a] = baseHi[a] - block0.lo[a];
  }
  baseBlock.resize(static_cast<std::size_t>(2 * block0.size[0] * block0.size[1] * block0.size[2]));
  blurBlock(blur0, block0.lo, baseHi, baseBlock.data());
  block0.mean = baseBlock.data();
  blurBlock(blur1, lo, hi, block);
}

/// Tile k of a run from its block (means then variances, `ny` rows of `width` voxels a
/// slice, `nz` slices): rows of (mean, variance) pairs, the layout the gathers read
/// (LevelGrid's tiled strides). A partial tile's other voxels are never read.
inline void blockToTile(const float* block, std::int64_t width, std::int64_t ny, std::int64_t nz,
  std::int64_t k, float* tile)
{
  const std::int64_t plane = width * ny * nz;
  const std::int64_t x0 = k * kTileSide, x1 = std::min(width, x0 + kTileSpan);
  for (std::int64_t z = 0; z < nz; ++z)
    for (std::int64_t y = 0; y < ny; ++y)
    {
      const float* mean = block + (z * ny + y) * width;
      const float* variance = mean + plane;
      float* to = tile + 2 * (z * kTileSpan + y) * kTileSpan;
      for (std::int64_t x = x0; x < x1; ++x)
      {
        to[2 * (x - x0)] = mean[x];
        to[2 * (x - x0) + 1] = variance[x];
      }
    }
}

} // namespace

/// Each worker takes runs of marked tiles and, per run, two passes: the blur of the run's
/// voxels into a block (level 0 from the volume; level 1 through the block of level 0 its
/// taps read), then the block's rows into the run's tiles, each tile put in use once whole.
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
  return parallelFor(count, chunks, threads, execution,
    [&](std::int64_t begin, std::int64_t end, ChunkProgress& progress)
    {
      SliceBlur<RawSource<T>> blur0(source, plan0);
      StoredSource<BlockVoxels> base{ {}, plan0.out,
        this->Shift }; // level 1: the block of level 0 its taps read
      SliceBlur<StoredSource<BlockVoxels>> blur1(base, plan1);
      std::vector<float> block, baseBlock; // a run's voxels before they go to their tiles
      for (std::int64_t r = begin; r < end; ++r)
      {
        const TileRun& run = runs[static_cast<std::size_t>(r)];
        std::int64_t lo[3], hi[3];
        runVoxels(run.first, run.count, this->Tiles, n, lo, hi);
        const std::int64_t width = hi[0] - lo[0], rows = (hi[1] - lo[1]) * (hi[2] - lo[2]);
        block.resize(static_cast<std::size_t>(2 * width * rows));
        if (this->Level == 0)
          blurBlock(blur0, lo, hi, block.data());
        else
          blurFromLevel0(blur0, blur1, base.at, plan0.out, lo, hi, baseBlock, block.data());
        for (std::int64_t k = 0; k < run.count; ++k)
        {
          blockToTile(block.data(), width, hi[1] - lo[1], hi[2] - lo[2], k,
            this->Pool.data() + this->Offsets[run.first + k]);
          this->State[run.first + k].store(kInUse, std::memory_order_release);
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

} // namespace detail

bool PyramidTiles::buildMarked(const Execution& execution)
{
  for (int l = 0; l < this->count(); ++l)
  {
    if (!this->levels[l]->buildMarked(
          detail::pyramidStageExecution(execution, l, l, this->count())))
      return false;
  }
  return true;
}

std::size_t PyramidTiles::builtBytes(std::size_t from) const
{
  std::size_t bytes = 0;
  for (std::size_t l = from; l < this->levels.size(); ++l)
    bytes += static_cast<std::size_t>(this->levels[l]->builtTiles()) * kTileBytes;
  return bytes;
}

void PyramidTiles::forgetMarks()
{
  for (const auto& level : this->levels)
    level->forgetMarks();
}

void PyramidTiles::settle()
{
  for (const auto& level : this->levels)
    level->settle();
}

void PyramidTiles::releaseBehind(bool up)
{
  // Level l goes while its tiles and the coarser ones' take more than keptBytes: a finer
  // level's tiles are released to keep the coarser ones, never the other way.
  for (std::size_t l = 0; l < this->levels.size(); ++l)
  {
    // From the farthest layer behind to the farthest one marked (none: every layer).
    detail::LevelTiles& level = *this->levels[l];
    const std::int64_t top = level.layerCount() - 1;
    const bool marked = level.highestMarked() >= 0;
    const std::int64_t layers = !marked ? top + 1
      : up                              ? level.highestMarked() + 1
                                        : top + 1 - level.lowestMarked();
    for (std::int64_t k = 0; k<layers&& this->builtBytes(l)> this->keptBytes; ++k)
      level.releaseLayer(up ? k : top - k);
  }
}

} // namespace vao
