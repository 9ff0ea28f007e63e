// The SurfacePyramid (vao/VarianceOcclusionMap.h): levels 0 and 1 in tiles built on
// demand (LevelTiles.h), and level 2 blurred from their slices as they stream past, so
// neither whole level ever exists.
#include "vao/Storage.h"
#include "vao/Validation.h"
#include "vao/VarianceOcclusionMap.h"

#include "cpu/moment_pyramid/LevelTiles.h"
#include "cpu/moment_pyramid/PyramidBlur.h"

#include <algorithm>
#include <memory>
#include <vector>

namespace vao
{

namespace
{
using namespace detail;
using namespace detail::pyramid;

// The tiles a query keeps by default: a fifth of the input's bytes, and at least 16 MiB.
// The bone surface of a 512x512x209 int16 CT head reaches 73% of it in tiles (13,010
// of them); kept this way, the filter's extra memory is 43% of the input (vao_memory).
// A small volume keeps all its tiles: every query after the first builds none.
constexpr std::size_t kKeptTilesPerInputByte = 5;
constexpr std::size_t kKeptTilesAtLeast = std::size_t(16) << 20;

/// One level's slices, computed as the next level needs them into a ring of the five a
/// slice of the next level reads (each thread its own).
template <class Source>
class SliceRing
{
public:
  SliceRing(const Source& source, const BlurPlan& plan)
    : Blur(source, plan)
    , Dims(plan.out)
    , Plane(plan.out[0] * plan.out[1])
  {
    this->Data.resize(static_cast<std::size_t>(2 * kTaps * this->Plane));
    std::fill(this->Tags, this->Tags + kTaps, std::int64_t(-1));
  }

  const Index3& dims() const { return this->Dims; }
  /// Slice z's means and variances (computed by the last make(z)).
  std::pair<const float*, const float*> operator()(std::int64_t z) const
  {
    const float* mean = this->Data.data() + 2 * (z % kTaps) * this->Plane;
    return { mean, mean + this->Plane };
  }
  /// Computes slice z unless the ring holds it; `inputs(z)` first makes what it reads.
  template <class Inputs>
  void make(std::int64_t z, Inputs&& inputs)
  {
    if (this->Tags[z % kTaps] == z)
      return;
    inputs(z);
    float* mean = this->Data.data() + 2 * (z % kTaps) * this->Plane;
    this->Blur.slice(z,
      [&](std::int64_t yo) {
        return std::make_pair(mean + yo * this->Dims[0], mean + this->Plane + yo * this->Dims[0]);
      });
    this->Tags[z % kTaps] = z;
  }

private:
  SliceBlur<Source> Blur;
  Index3 Dims;
  std::int64_t Plane;
  StorageArray<float> Data;
  std::int64_t Tags[kTaps];
};

/// The voxels of a SliceRing's slices, as the source of the next level.
template <class Ring>
struct RingVoxels
{
  const Ring* ring;
  std::pair<const float*, const float*> operator()(
    std::int64_t x, std::int64_t y, std::int64_t z) const
  {
    const auto slice = (*ring)(z);
    const std::int64_t offset = y * ring->dims()[0] + x;
    return { slice.first + offset, slice.second + offset };
  }
};

/// The input slices (of a level of dims n) that output slice zo of a step-2 blur reads.
template <class F>
void forInputSlices(std::int64_t zo, const Index3& n, F&& f)
{
  for (int k = 0; k < kTaps; ++k)
    f(std::min(std::max<std::int64_t>(2 * zo + k - kHalf, 0), n[2] - 1));
}

/// Level 2 blurred from level 1 blurred from level 0 (`raw` blurred keeping every
/// `firstStep`-th voxel), levels 0 and 1 streaming through rings of slices: the same
/// slices, hence the same level 2, as from the whole levels. Returns false when cancelled.
template <class T>
bool blurThroughStreamedLevels(const RawSource<T>& raw, int firstStep, double shift,
  MomentLevel& out, const Execution& execution, int threads)
{
  const BlurPlan plan0(raw.dims(), firstStep, shift);
  const BlurPlan plan1(plan0.out, 2, shift);
  const BlurPlan plan2(plan1.out, 2, shift);
  out.dims = plan2.out;
  const auto outCount = static_cast<std::size_t>(plan2.out[0] * plan2.out[1] * plan2.out[2]);
  out.mean.resize(outCount);
  out.variance.resize(outCount);
  // One chunk a thread: each recomputes the slices it shares with the one before, and
  // each allocates its rings once (all at the start, so none reuses and keeps another's
  // freed block).
  const int chunks = static_cast<int>(std::min<std::int64_t>(plan2.out[2], std::max(1, threads)));
  return parallelFor(plan2.out[2], chunks, threads, execution,
    [&](std::int64_t zBegin, std::int64_t zEnd, ChunkProgress& progress)
    {
      using Ring0 = SliceRing<RawSource<T>>;
      using Source1 = StoredSource<RingVoxels<Ring0>>;
      using Ring1 = SliceRing<Source1>;
      Ring0 ring0(raw, plan0);
      const Source1 source1{ { &ring0 }, plan0.out, shift };
      Ring1 ring1(source1, plan1);
      const StoredSource<RingVoxels<Ring1>> source2{ { &ring1 }, plan1.out, shift };
      SliceBlur<StoredSource<RingVoxels<Ring1>>> blur2(source2, plan2);
      for (std::int64_t zo = zBegin; zo < zEnd; ++zo)
      {
        forInputSlices(zo, plan1.out,
          [&](std::int64_t z1)
          {
            ring1.make(z1,
              [&](std::int64_t) {
                forInputSlices(
                  z1, plan0.out, [&](std::int64_t z0) { ring0.make(z0, [](std::int64_t) {}); });
              });
          });
        blur2.slice(zo, levelRows(out.mean.data(), out.variance.data(), plan2.out, zo));
        if (!progress.advance())
        {
          return;
        }
      }
    });
}

Status buildSurfaceLevels(const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const PyramidParameters& parameters,
  SurfacePyramid& pyramid, const Execution& execution)
{
  SurfacePyramidAccess::levels(pyramid).clear();
  SurfacePyramidAccess::tiles(pyramid).reset();
  PyramidSetup setup;
  const Status status = preparePyramid(volume, origin, spacing, parameters, setup);
  if (!status.ok)
  {
    return status;
  }
  const int threads = resolveThreadCount(execution.threads);
  const double shift = setup.shift;
  const int levels = parameters.levels;
  std::vector<MomentLevel> result(static_cast<std::size_t>(levels));
  // Levels 0 and 1 are tiles; level 2, the first whole one, costs the three levels of
  // the whole build.
  const int tiled = std::min(levels, PyramidTiles::kLevels);
  result[0].dims = keptDims(volume.dims, setup.firstStep);
  if (levels >= 2)
    result[1].dims = keptDims(result[0].dims, 2);
  if (levels >= 3)
  {
    const bool done = dispatchScalarType(volume.type,
      [&](auto tag)
      {
        using T = decltype(tag);
        const RawSource<T> raw{ TypedVolume<T>(volume), shift };
        return blurThroughStreamedLevels(raw, setup.firstStep, shift, result[2],
          pyramidStageExecution(execution, 0, 2, levels), threads);
      });
    if (!done)
    {
      return Status::cancelled();
    }
  }
  if (!blurCoarserLevels(result, 3, shift, threads,
        [&](int l) { return pyramidStageExecution(execution, l, l, levels); }))
  {
    return Status::cancelled();
  }
  setLevelGeometry(result, origin, spacing, setup);
  auto tiles = std::make_unique<PyramidTiles>();
  tiles->keptBytes = std::max(kKeptTilesAtLeast,
    static_cast<std::size_t>(volume.voxelCount()) *
      dispatchScalarType(volume.type, [](auto tag) { return sizeof(tag); }) /
      kKeptTilesPerInputByte);
  std::int64_t tileCount = 0;
  for (int l = 0; l < tiled; ++l)
  {
    tileCount += LevelTiles::tilesOf(result[l].dims);
  }
  tiles->pool = std::make_unique<TilePool>(tileCount);
  for (int l = 0; l < tiled; ++l)
  {
    tiles->levels.emplace_back(
      new LevelTiles(*tiles->pool, volume, result[l], l, setup.firstStep, shift));
  }
  SurfacePyramidAccess::tiles(pyramid) = std::move(tiles);
  SurfacePyramidAccess::levels(pyramid) = std::move(result);
  return Status::success();
}

} // namespace

SurfacePyramid::SurfacePyramid() = default;
SurfacePyramid::~SurfacePyramid() = default;
SurfacePyramid::SurfacePyramid(SurfacePyramid&& other) noexcept = default;
SurfacePyramid& SurfacePyramid::operator=(SurfacePyramid&& other) noexcept = default;

void SurfacePyramid::clear()
{
  this->Levels.clear();
  this->Tiles.reset();
}

std::int64_t SurfacePyramid::builtTiles(int level) const
{
  const detail::LevelTiles* tiles = this->Tiles ? this->Tiles->at(level) : nullptr;
  return tiles ? tiles->builtTiles() : 0;
}

std::size_t SurfacePyramid::tileMemory() const
{
  return this->Tiles && this->Tiles->pool ? this->Tiles->pool->bytes() : 0;
}

std::size_t SurfacePyramid::keptTileBytes() const
{
  return this->Tiles ? this->Tiles->keptBytes : 0;
}

void SurfacePyramid::setKeptTileBytes(std::size_t bytes)
{
  if (this->Tiles)
    this->Tiles->keptBytes = bytes;
}

std::int64_t SurfacePyramid::tileCount(int level) const
{
  const detail::LevelTiles* tiles = this->Tiles ? this->Tiles->at(level) : nullptr;
  return tiles ? tiles->tileCount() : 0;
}

Status buildSurfacePyramid(const VolumeView& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const PyramidParameters& parameters,
  SurfacePyramid& pyramid, const Execution& execution)
{
  const Status status = catchOutOfMemory("the levels of the moment pyramid",
    [&] { return buildSurfaceLevels(volume, origin, spacing, parameters, pyramid, execution); });
  if (!status.ok)
  {
    pyramid.clear();
  }
  return status;
}

} // namespace vao
