// Levels 0 and 1 of a SurfacePyramid (vao/VarianceOcclusionMap.h), kept in tiles of 8^3
// cells built only where the surface queries sample: a query first marks the tiles its
// samples touch, then buildMarked blurs those tiles from the volume (PyramidBlur.h, the
// same arithmetic as the whole level: level 1's tiles blur a block of level 0 computed
// for them), then the query samples; SurfaceWalk.h does this slab by slab and releases
// the layers of tiles a sweep leaves behind. The bone surface of the CT head reaches a
// tenth of level 0's tiles and a fifth of level 1's; the two levels held 96% of a whole
// pyramid.
//
// Layout. Tile (tx, ty, tz) serves the trilinear cells whose lower corner lies in
// [8 tx, 8 tx + 8) x ... and holds the 9^3 voxels those cells read, [8 tx, 8 tx + 9) x
// ... (the ninth is the next tile's first again): 1458 floats, the (mean, variance) pairs
// of its voxels, x fastest, so a sample reads one tile and a corner's two numbers are
// one 8-byte load. Built tiles take slots of one pool, found through a table of float
// offsets (LevelGrid's tileOffsets); a released tile's slot goes to the next tile built.
// The pool is a reservation whose pages the system backs when first written
// (allocateSparseStorage): its memory is the most tiles held at once, and reusing slots
// costs no page fault (on some virtual machines a fault costs more than a tile's blur).
#pragma once

#include "vao/VarianceOcclusionMap.h"

#include "cpu/moment_pyramid/LevelGrid.h"

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

namespace vao
{
namespace detail
{

constexpr int kTileShift = 3;
constexpr std::int64_t kTileSide = 1 << kTileShift; // cells per tile and axis
constexpr std::int64_t kTileSpan = kTileSide + 1;   // voxels per tile and axis
constexpr std::int64_t kTileFloats = 2 * kTileSpan * kTileSpan * kTileSpan;

/// The slots that the tiled levels' tiles take (kTileFloats floats each): a reservation
/// backed as far as slots were ever handed out, released slots going to the next tiles.
class TilePool
{
public:
  /// Room for `tiles` tiles, or for as many as 32-bit float offsets reach (1.47 M tiles,
  /// 8.6 GB held at once). Throws std::bad_alloc when the address space is not there.
  explicit TilePool(std::int64_t tiles);
  ~TilePool();
  TilePool(const TilePool&) = delete;
  TilePool& operator=(const TilePool&) = delete;

  float* data() const { return this->Pool; }
  /// A slot's first float. Throws std::bad_alloc when the pool is full.
  std::int32_t take();
  void give(std::int32_t offset) { this->Free.push_back(offset); }
  /// Backs the slots handed out since the last call, in one call, not a fault a page (on
  /// some virtual machines a fault costs more than blurring a tile). Throws
  /// std::bad_alloc when the system has no memory for them.
  void prepare();
  /// The memory of the slots ever handed out: the most tiles held at once.
  std::size_t bytes() const;
  /// The slots handed out and not given back.
  std::int64_t taken() const { return this->Used - static_cast<std::int64_t>(this->Free.size()); }

private:
  float* Pool = nullptr;
  std::size_t Bytes = 0;
  std::int32_t Capacity = 0; // slots
  std::int32_t Used = 0;     // slots ever handed out
  std::int32_t Prepared = 0; // slots backed
  std::vector<std::int32_t> Free;
};

class LevelTiles
{
public:
  /// Level `level` (0 or 1) of the pyramid of `volume` whose level 0 keeps every
  /// `firstStep`-th voxel (its dims in `geometry`, whose arrays stay empty), moments
  /// shifted by `shift`, its tiles in `pool` (which must outlive it). Throws std::bad_alloc
  /// when it cannot); builds nothing. The volume is read whenever tiles are built: it must
  /// outlive this object, unchanged.
  LevelTiles(TilePool& pool, const VolumeView& volume, const MomentLevel& geometry, int level,
    int firstStep, double shift);
  ~LevelTiles();
  LevelTiles(const LevelTiles&) = delete;
  LevelTiles& operator=(const LevelTiles&) = delete;

  /// The level's geometry (dims, origin, spacing, kernel radius, rounding variance).
  const MomentLevel& level() const { return this->Geometry; }

  /// The level as the samplers read it (valid in the tiles built).
  const LevelGrid& grid() const { return this->Grid; }

  /// Marks the tiles holding the corners of the trilinear cell at world (x, y, z), clamped
  /// to the level with the samplers' own arithmetic (the tests compare every query with
  /// the whole pyramid bit for bit, so a sample outside its marked tiles would show).
  /// Any thread. Inline: a shadow query marks five samples a point.
  void markAround(double x, double y, double z)
  {
    // The cell's lower corner as trilinearSample finds it, from the same grid numbers: the
    // cell's tile holds all its corners.
    const std::int64_t tile[3] = { this->tileAlong(0, x), this->tileAlong(1, y),
      this->tileAlong(2, z) };
    std::atomic<std::uint8_t>& state =
      this->State[(tile[2] * this->Tiles[1] + tile[1]) * this->Tiles[0] + tile[0]];
    const std::uint8_t now = state.load(std::memory_order_relaxed);
    // Marked or in use: marked since forgetMarks, its layer already among those marked
    // (the points of a batch are neighbours: most of their samples share a tile).
    if (now == kMarked || now == kInUse)
      return;
    std::int64_t lowest = this->LowestMarked.load(std::memory_order_relaxed);
    while (tile[2] < lowest &&
      !this->LowestMarked.compare_exchange_weak(lowest, tile[2], std::memory_order_relaxed))
    {
    }
    std::int64_t highest = this->HighestMarked.load(std::memory_order_relaxed);
    while (tile[2] > highest &&
      !this->HighestMarked.compare_exchange_weak(highest, tile[2], std::memory_order_relaxed))
    {
    }
    if (now == kAbsent)
      state.store(kMarked, std::memory_order_relaxed);
    else if (now == kBuilt)
      state.store(kInUse, std::memory_order_relaxed);
  }

  /// Builds the tiles marked and not built yet, on the execution's threads. Returns false
  /// when cancelled (the tiles finished stay built).
  bool buildMarked(const Execution& execution);

  /// The layer of tiles (along z) holding world z, clamped to the level.
  std::int64_t layerOf(double z) const { return this->tileAlong(2, z); }
  std::int64_t layerCount() const { return this->Tiles[2]; }
  /// The lowest and highest layers markAround reached since forgetMarks (layerCount()
  /// and -1 when none). forgetMarks also ends the use of the tiles marked.
  std::int64_t lowestMarked() const { return this->LowestMarked.load(std::memory_order_relaxed); }
  std::int64_t highestMarked() const { return this->HighestMarked.load(std::memory_order_relaxed); }
  void forgetMarks();
  /// Leaves every tile absent or built, as a query finds them: what an aborted one left
  /// marked goes (giving back its slot if it had one), what it left in use is built.
  void settle();
  /// Frees the slots of layer `layer`'s built tiles not in use for other tiles; they are
  /// built again when marked again. Not while tiles are being marked, built or sampled.
  void releaseLayer(std::int64_t layer);

  std::int64_t builtTiles() const { return this->Built.load(std::memory_order_relaxed); }
  /// Tiles built since construction, those built again after a release included.
  std::int64_t madeTiles() const { return this->Made.load(std::memory_order_relaxed); }
  std::int64_t tileCount() const { return this->Tiles[0] * this->Tiles[1] * this->Tiles[2]; }
  /// The tiles of a level of `dims` voxels.
  static std::int64_t tilesOf(const Index3& dims);

private:
  /// The tile coordinate along axis a of the cell holding world coordinate p (its lower
  /// corner as trilinearSample finds it, clamped to the level).
  std::int64_t tileAlong(int a, double p) const
  {
    const LevelGrid& g = this->Grid;
    const double u =
      std::min(std::max((p - g.origin[a]) * g.inverseSpacing[a], 0.0), g.maxIndex[a]);
    return static_cast<std::int64_t>(u) >> kTileShift;
  }

  struct TileRun
  {
    std::int64_t first, count; // tiles first, first + 1, ... along x
  };
  template <class T>
  bool build(const std::vector<TileRun>& runs, const Execution& execution);
  void setGeometry(const MomentLevel& geometry);
  void prepareGrid();

  VolumeView Volume;
  MomentLevel Geometry;
  int Level;
  int FirstStep;
  double Shift;
  Index3 Tiles;
  // A tile is absent, marked (to build), slotted (given its slot, being built), built, or
  // in use (built and marked since forgetMarks: the samples to come read it).
  enum : std::uint8_t
  {
    kAbsent,
    kMarked,
    kSlotted,
    kBuilt,
    kInUse
  };
  std::unique_ptr<std::atomic<std::uint8_t>[]> State;
  // A tile's first float in the pool; 0 (a slot that can be read) for a tile without one:
  // lanes that pad a batch or have left the volume read their clamped cell's tile, and
  // their samples are discarded.
  std::unique_ptr<std::int32_t[]> Offsets;
  std::atomic<std::int64_t> Built{ 0 }, Made{ 0 };
  std::atomic<std::int64_t> LowestMarked{ 0 }, HighestMarked{ -1 };
  TilePool& Pool;
  LevelGrid Grid;
};

} // namespace detail

/// The tiled levels of a SurfacePyramid (levels 0 and 1, as many as it has).
class PyramidTiles
{
public:
  static constexpr int kLevels = 2;
  static constexpr std::size_t kTileBytes = detail::kTileFloats * sizeof(float);
  std::unique_ptr<detail::TilePool> pool; // the levels' tiles, declared first: it outlives them
  std::vector<std::unique_ptr<detail::LevelTiles>> levels;
  /// The built tiles' memory a query keeps (SurfaceWalk.h): past it, it releases the
  /// layers its sweep has left behind.
  std::size_t keptBytes = static_cast<std::size_t>(-1);
  /// The direction of the next sweep along z. Each turns back: it starts where the last
  /// one ended, among the tiles that one kept, so those take no room beside the ones it
  /// builds first.
  bool upward = true;

  /// Level l's tiles, or nullptr when level l is whole.
  detail::LevelTiles* at(int l) const
  {
    return l >= 0 && l < static_cast<int>(this->levels.size()) ? this->levels[l].get() : nullptr;
  }
  int count() const { return static_cast<int>(this->levels.size()); }
  /// buildMarked of every tiled level.
  bool buildMarked(const Execution& execution);
  /// The bytes of the built tiles of levels `from` and up.
  std::size_t builtBytes(std::size_t from = 0) const;
  void forgetMarks();
  /// settle of every tiled level.
  void settle();
  /// Releases the tiles not in use that a sweep along z going `up` has left behind or
  /// passes (in the layers up to its highest marked one; going down, down to its lowest;
  /// every layer when none is marked), farthest first: level 0's while more than
  /// keptBytes are built, then level 1's while level 1 alone takes more. (A tile of level
  /// 1 costs about fifteen of level 0 to build: it blurs the block of level 0 under it.)
  void releaseBehind(bool up);
};

} // namespace vao

namespace vao
{
/// The builder's and the queries' way into a SurfacePyramid.
struct SurfacePyramidAccess
{
  static std::vector<MomentLevel>& levels(SurfacePyramid& pyramid) { return pyramid.Levels; }
  static std::unique_ptr<PyramidTiles>& tiles(SurfacePyramid& pyramid) { return pyramid.Tiles; }
};
} // namespace vao
