// Bounds of what the rest of a shadow march can meet on its last level. Past its first
// steps a march stays on the pyramid's coarsest level with steps of one length along the
// light, and most of those steps (on the CT head's bone surface, 75% of the bound checks
// there) come after the last sample that could still raise a lane's occlusion. Per light,
// each cell here holds the largest mean and variance of the cell bounds (CellBounds in
// LevelGrid.h) of every cell that a march from a position in it reaches, that cell and
// all later steps included; a lane whose Chebyshev bound from them cannot exceed its
// occlusion stops, which changes no maximum.
#pragma once

#include "cpu/moment_pyramid/LevelGrid.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <vector>

namespace vao
{
namespace detail
{

class RayBounds
{
public:
  /// The bounds of `grid` (which has cellBounds) for steps of `step` world units along the
  /// unit `light`.
  RayBounds(const LevelGrid& grid, double step, const std::array<double, 3>& light)
  {
    std::int64_t n[3], top[3];
    bool forward[3];
    Reach reach[3];
    for (int a = 0; a < 3; ++a)
    {
      n[a] = static_cast<std::int64_t>(grid.maxIndex[a]) + 1;
      // The last cell along a, as cellsOf finds it: x's last voxel is the upper corner of
      // the cell below it where the rows are paired.
      top[a] = a == 0 && grid.pairedRows ? n[a] - 2 : n[a] - 1;
      const double move = step * light[a] * grid.inverseSpacing[a]; // one step in index units
      forward[a] = move > 0;
      reach[a] = reachable(move, top[a], grid.maxIndex[a]);
    }
    const float* cells = grid.cellBounds;
    this->pairs.assign(cells, cells + 2 * n[0] * n[1] * n[2]);
    // Every cell reached from a cell lies towards the move along each axis (or level with
    // it), so taking the cells in that order from the far side finds each one's successors
    // done.
    auto along = [&](int a, std::int64_t i) { return forward[a] ? top[a] - i : i; };
    for (std::int64_t iz = 0; iz <= top[2]; ++iz)
      for (std::int64_t iy = 0; iy <= top[1]; ++iy)
        for (std::int64_t ix = 0; ix <= top[0]; ++ix)
        {
          const std::int64_t c[3] = { along(0, ix), along(1, iy), along(2, iz) };
          float* at = &this->pairs[2 * ((c[2] * n[1] + c[1]) * n[0] + c[0])];
          for (std::int64_t z = reach[2].first[c[2]]; z <= reach[2].last[c[2]]; ++z)
            for (std::int64_t y = reach[1].first[c[1]]; y <= reach[1].last[c[1]]; ++y)
              for (std::int64_t x = reach[0].first[c[0]]; x <= reach[0].last[c[0]]; ++x)
              {
                const float* next = &this->pairs[2 * ((z * n[1] + y) * n[0] + x)];
                at[0] = std::max(at[0], next[0]);
                at[1] = std::max(at[1], next[1]);
              }
        }
  }

  /// (mean, variance) pairs indexed like the level's voxels (a cell by its lower corner).
  const float* data() const { return this->pairs.data(); }

private:
  /// Along one axis, the first and last cells that one step reaches from each cell.
  struct Reach
  {
    std::vector<std::int64_t> first, last;
  };

  /// The cells 0..top along an axis of maxIndex + 1 voxels that one step of `move` (index
  /// units) reaches from each: its positions move only towards the move's sign (the
  /// rounding of start + t light is monotone in t), by the move give or take a rounding.
  /// The first and last cells hold every position beyond them (cellsOf clamps).
  static Reach reachable(double move, std::int64_t top, double maxIndex)
  {
    constexpr double kSlack = 1e-6; // index units: far above the positions' rounding
    auto cellOf = [&](double u)
    {
      return std::min(
        top, static_cast<std::int64_t>(std::floor(std::min(std::max(u, 0.0), maxIndex))));
    };
    Reach reach;
    reach.first.resize(static_cast<std::size_t>(top + 1));
    reach.last.resize(static_cast<std::size_t>(top + 1));
    for (std::int64_t c = 0; c <= top; ++c)
    {
      std::int64_t low = c, high = c;
      if (move > 0)
      {
        low = c == 0 ? 0 : std::max(c, cellOf(c + move - kSlack));
        high = c == top ? top : cellOf(c + 1 + move + kSlack);
      }
      else if (move < 0)
      {
        low = c == 0 ? 0 : cellOf(c + move - kSlack);
        high = c == top ? top : std::min(c, cellOf(c + 1 + move + kSlack));
      }
      reach.first[c] = low;
      reach.last[c] = high;
    }
    return reach;
  }

  std::vector<float> pairs;
};

} // namespace detail
} // namespace vao
