// Levels 0 and 1 of a SurfacePyramid (vao/VarianceOcclusionMap.h), kept in tiles of 8^3
// voxels built only where the surface queries sample: a query first marks the tiles its
// samples touch, then buildMarked blurs those tiles from the volume (PyramidBlur.h, the
// same arithmetic as the whole level: level 1's tiles blur a block of level 0 computed
// for them), then the query samples; SurfaceSweep.h does this slab by slab and releases
// the layers of tiles a sweep leaves behind. The bone surface of the CT head reaches a
// tenth of level 0's tiles and a fifth of level 1's; the two levels held 96% of a whole
// pyramid.
//
// Layout. Tile (tx, ty, tz), x fastest, is 1024 floats: the (mean, variance) pairs of its
// voxels, x fastest within the tile, so a tile is one 4 KiB page and a corner's two
// numbers are one 8-byte load. The tiles live at fixed places in one reservation of the whole level's size whose
// pages the system backs only when written (allocateSparseStorage): the index of a voxel
// is arithmetic (LevelGrid's tiled form), and the memory used is the tiles built.
#pragma once

#include "vao/VarianceOcclusionMap.h"

#include "LevelGrid.h"

#include <atomic>
#include <cstdint>
#include <memory>
#include <vector>

namespace vao
{
namespace detail
{

constexpr int kTileShift = 3;
constexpr std::int64_t kTileSide = 1 << kTileShift;
constexpr std::int64_t kTileVoxels = kTileSide * kTileSide * kTileSide;

class LevelTiles
{
public:
  /// Level `level` (0 or 1) of the pyramid of `volume` whose level 0 keeps every
  /// `firstStep`-th voxel (its dims in `geometry`, whose arrays stay empty), moments
  /// shifted by `shift`. Reserves the whole level's address space (throws std::bad_alloc
  /// when it cannot); builds nothing. The volume is read whenever tiles are built: it must
  /// outlive this object, unchanged.
  LevelTiles(const VolumeView& volume, const MomentLevel& geometry, int level, int firstStep, double shift);
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
  /// Any thread.
  void markAround(double x, double y, double z);

  /// Builds the tiles marked and not built yet, on the execution's threads. Returns false
  /// when cancelled (the tiles finished stay built).
  bool buildMarked(const Execution& execution);

  /// The layer of tiles (along z) holding world z, clamped to the level.
  std::int64_t layerOf(double z) const;
  std::int64_t layerCount() const { return this->Tiles[2]; }
  /// The lowest layer markAround reached since forgetMarks (layerCount() when none).
  std::int64_t lowestMarked() const { return this->LowestMarked.load(std::memory_order_relaxed); }
  void forgetMarks();
  /// Gives the memory of layer `layer`'s built tiles back; they are built again when
  /// marked again. Not while tiles are being marked, built or sampled.
  void releaseLayer(std::int64_t layer);

  std::int64_t builtTiles() const { return this->Built.load(std::memory_order_relaxed); }
  /// Tiles built since construction, those built again after a release included.
  std::int64_t madeTiles() const { return this->Made.load(std::memory_order_relaxed); }
  std::int64_t tileCount() const { return this->Tiles[0] * this->Tiles[1] * this->Tiles[2]; }

private:
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
  std::unique_ptr<std::atomic<std::uint8_t>[]> State; // 0 absent, 1 marked, 2 built
  std::atomic<std::int64_t> Built{ 0 }, Made{ 0 };
  std::atomic<std::int64_t> LowestMarked{ 0 };
  float* Pool = nullptr;
  std::size_t PoolBytes = 0;
  LevelGrid Grid;
};

/// The tiled levels of a SurfacePyramid (levels 0 and 1, as many as it has).
class PyramidTiles
{
public:
  static constexpr int kLevels = 2;
  static constexpr std::size_t kTileBytes = 2 * kTileVoxels * sizeof(float);
  std::vector<std::unique_ptr<LevelTiles>> levels;
  /// The built tiles' memory a query keeps (SurfaceSweep.h): past it, it releases the
  /// layers its sweep has left behind.
  std::size_t keptBytes = static_cast<std::size_t>(-1);

  /// Level l's tiles, or nullptr when level l is whole.
  LevelTiles* at(int l) const { return l >= 0 && l < static_cast<int>(this->levels.size()) ? this->levels[l].get() : nullptr; }
  int count() const { return static_cast<int>(this->levels.size()); }
  /// buildMarked of every tiled level.
  bool buildMarked(const Execution& execution);
  std::size_t builtBytes() const;
  void forgetMarks();
  /// Releases the layers below each level's lowest marked one (those a sweep up along z
  /// has left behind), lowest first: level 0's while more than keptBytes are built, then
  /// level 1's while level 1 alone takes more. (A tile of level 1 costs about fifteen of
  /// level 0 to build: it blurs the block of level 0 under it.)
  void releaseBelowMarks();
};

} // namespace detail
} // namespace vao

namespace vao
{
/// The builder's and the queries' way into a SurfacePyramid.
struct SurfacePyramidAccess
{
  static std::vector<MomentLevel>& levels(SurfacePyramid& pyramid) { return pyramid.Levels; }
  static std::unique_ptr<detail::PyramidTiles>& tiles(SurfacePyramid& pyramid) { return pyramid.Tiles; }
};
} // namespace vao
