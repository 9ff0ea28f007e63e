// The levels a surface query (SurfaceSampling.cxx) samples, prepared once per query: their
// grids (whole or tiled), kernel radii, and the cell and ray bounds of the shadow march.
#pragma once

#include "vao/VarianceOcclusionMap.h"

#include "cpu/moment_pyramid/LevelTiles.h"
#include "cpu/moment_pyramid/RayBounds.h"
#include "cpu/moment_pyramid/SurfaceLanes.h"

#include <array>
#include <vector>

namespace vao
{
namespace detail
{

/// The levels a query uses, prepared for sampling.
struct PreparedPyramid
{
  std::vector<LevelGrid> grids;
  std::vector<double> kernelRadius;

  // The vector march applies: the processor has AVX2 (or AVX-512, `tier`) and every
  // level's indices fit in 32 bits.
  SimdTier tier = cpuSimdTier();
  bool vectorMarch = tier >= SimdTier::Avx2;

  /// `tiles`: a SurfacePyramid's tiled levels (read where their tiles are built).
  PreparedPyramid(const std::vector<MomentLevel>& pyramid, int levels, const PyramidTiles* tiles)
  {
    for (int l = 0; l < levels; ++l)
    {
      const LevelTiles* tiled = tiles ? tiles->at(l) : nullptr;
      this->grids.push_back(tiled ? tiled->grid() : LevelGrid(pyramid[l]));
      this->levels.push_back(&pyramid[l]);
      this->kernelRadius.push_back(pyramid[l].kernelRadius);
      this->vectorMarch = this->vectorMarch && this->grids.back().narrowIndices;
    }
  }

  /// Cell bounds for the vector march on the whole levels of at most one voxel a point
  /// (building them reads the level once): the coarsest, where most of a march's steps
  /// fall. (The next level, with 8 voxels a point, holds few of a march's steps: its bounds
  /// would cost memory for little.)
  void boundCells(std::int64_t count)
  {
    this->bounds.reserve(this->grids.size());
    for (std::size_t l = 0; l < this->grids.size() && this->vectorMarch; ++l)
    {
      if (!this->grids[l].tiled && this->levels[l]->mean.size() <= static_cast<std::size_t>(count))
        this->bounds.emplace_back(*this->levels[l], this->grids[l]);
    }
  }

  /// The ray bounds of the last level, where it has cell bounds, for the march's steps
  /// along the unit `light`: they let a lane stop once nothing ahead can raise it, which
  /// saves more steps than building them costs.
  void boundRays(const std::array<double, 3>& light)
  {
    const int last = static_cast<int>(this->grids.size()) - 1;
    if (last >= 0 && this->grids[last].cellBounds)
      this->rays.emplace_back(
        this->grids[last], kMarchStepFraction * this->kernelRadius[last], light);
  }
  /// The ray bounds (null without them) and their level, the last.
  const float* rayBounds() const
  {
    return this->rays.empty() ? nullptr : this->rays.front().data();
  }
  int rayLevel() const { return static_cast<int>(this->grids.size()) - 1; }

private:
  std::vector<const MomentLevel*> levels;
  std::vector<CellBounds> bounds;
  std::vector<RayBounds> rays;
};

} // namespace detail
} // namespace vao
