// The tile of the fused pass's thread blocks (FusedStatistics.h, FusedExtrema.h): 32 x 8
// output columns, one per thread; 32 along x so that a warp reads whole rows.
#pragma once

#include "cuda/common/Pipeline.h"

namespace vao
{
namespace gpu
{

constexpr Index kTileX = 32;
constexpr Index kTileY = 8;
constexpr Index kTileColumns = kTileX * kTileY;

} // namespace gpu
} // namespace vao
