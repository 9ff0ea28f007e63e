// Occlusion sweeping on one block of a distributed volume: the stages of
// SweepingCore.h over a ghosted SweepLayout, and the face exchange of D and V_s.
#include "vao/BlockSweeping.h"
#include "vao/Validation.h"

#include "cpu/common/Parallel.h"
#include "cpu/occlusion_sweeping/SweepingCore.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <new>
#include <sstream>
#include <vector>

namespace vao
{
namespace
{

using namespace detail::sweeping;

constexpr float kInfinity = std::numeric_limits<float>::infinity();
constexpr int kFaceValues = 5; // D and four V_s per face voxel
const char* const kSweepBuffers =
  "the sweeping buffers (signed distance, fixed voxels, octant visibility)";

SweepLayout blockLayout(const BlockPlacement& b, const std::array<double, 3>& spacing)
{
  const Index3 storage = { b.size[0] + 2, b.size[1] + 2, b.size[2] + 2 };
  return { Grid(storage, inSweepUnits(spacing)), { 1, 1, 1 }, b.size, b.begin, b.whole, true };
}

Status validatePlacement(const VolumeView& scalars, const BlockPlacement& b)
{
  std::ostringstream why;
  for (int a = 0; a < 3 && why.tellp() == 0; ++a)
  {
    if (b.whole[a] < 2)
    {
      why << "occlusion sweeping needs a 3-D volume with at least 2 voxels per axis (got "
          << b.whole[0] << " x " << b.whole[1] << " x " << b.whole[2] << ")";
    }
    else if (b.size[a] < 1 || b.begin[a] < 0 || b.begin[a] + b.size[a] > b.whole[a])
    {
      why << "the block [" << b.begin[a] << ", " << b.begin[a] + b.size[a] << ") on axis " << a
          << " is empty or outside the whole volume [0, " << b.whole[a] << ")";
    }
  }
  const Index3 expected = b.scalarDims();
  if (why.tellp() == 0 && scalars.dims != expected)
  {
    why << "the block's scalars must cover its voxels and one ghost layer on every face with "
           "a neighbour: "
        << expected[0] << " x " << expected[1] << " x " << expected[2] << " voxels (got "
        << scalars.dims[0] << " x " << scalars.dims[1] << " x " << scalars.dims[2] << ")";
  }
  const std::string message = why.str();
  return message.empty() ? Status::success() : Status::failure(message);
}

/// |new - old| of an exchanged value; infinite when exactly one of them is infinite.
double changeOf(float before, float after)
{
  if (before == after)
  {
    return 0.0;
  }
  const double change = std::abs(static_cast<double>(after) - before);
  return std::isfinite(change) ? change : std::numeric_limits<double>::infinity();
}

} // namespace

struct BlockSweeper::State
{
  VolumeView scalars;
  BlockPlacement placement;
  std::array<double, 3> spacing;
  SweepParameters parameters;
  Execution execution;
  SweepLayout layout;
  int threads = 1;
  double maskCount = 0.0;
  bool initialised = false;
  bool surfaceFound = false;
  StorageArray<float> distance; // storage-sized, ghosts included
  FixedMask fixed;
  VisibilityStore vis; // all eight octants, kept

  State(const VolumeView& v, const BlockPlacement& b, const std::array<double, 3>& h,
    const SweepParameters& p, const Execution& e)
    : scalars(v)
    , placement(b)
    , spacing(h)
    , parameters(p)
    , execution(e)
    , layout(blockLayout(b, h))
  {
    for (bool m : p.octantMask)
      this->maskCount += m;
  }

  /// Calls f(storage index, value index) for every voxel of the face's layer: the own
  /// voxels' outermost layer (ghost = false) or the ghost layer beyond it. The face voxels
  /// run over the other two axes, the lower one fastest.
  template <class F>
  void forFaceVoxels(int face, bool ghost, F&& f) const
  {
    const Index3& n = this->layout.size;
    const int axis = face / 2, u = axis == 0 ? 1 : 0, w = axis == 2 ? 1 : 2;
    const bool high = face & 1;
    std::int64_t position[3];
    position[axis] = high ? (ghost ? n[axis] : n[axis] - 1) : (ghost ? -1 : 0);
    std::int64_t k = 0;
    for (position[w] = 0; position[w] < n[w]; ++position[w])
      for (position[u] = 0; position[u] < n[u]; ++position[u])
        f(this->layout.index(position[0], position[1], position[2]), k++);
  }

  /// The four octants whose sweeps cross the face moving in direction `side` on its axis.
  static std::array<int, 4> octantsMoving(int axis, int side)
  {
    std::array<int, 4> octants{};
    int count = 0;
    for (int s = 0; s < 8; ++s)
      if (sweepDirection(s)[axis] == side)
        octants[count++] = s;
    return octants;
  }
};

BlockSweeper::BlockSweeper(const VolumeView& scalars, const BlockPlacement& placement,
  const std::array<double, 3>& spacing, const SweepParameters& parameters,
  const Execution& execution)
{
  try
  {
    this->Impl.reset(new State(scalars, placement, spacing, parameters, execution));
  }
  catch (const std::bad_alloc&)
  {
    // initialise() reports it: every call returns or does nothing until then.
  }
}

BlockSweeper::~BlockSweeper() = default;

Status BlockSweeper::initialise()
{
  if (!this->Impl)
  {
    return Status::noMemory("the block sweeper's state");
  }
  State& s = *this->Impl;
  Status status = validatePlacement(s.scalars, s.placement);
  if (status.ok)
  {
    status = validateSweep(s.scalars, s.spacing, s.parameters, SweepOutput{});
  }
  if (!status.ok)
  {
    return status;
  }
  return catchOutOfMemory(kSweepBuffers,
    [&]
    {
      const std::int64_t count = s.layout.storage.count;
      s.distance.assign(static_cast<std::size_t>(count), kInfinity); // ghosts: the open sky
      s.vis = VisibilityStore();
      s.vis.computed.fill(true);
      s.vis.keep(s.layout.storage, nullptr);
      std::fill(s.vis.storage.begin(), s.vis.storage.end(), 1.0f); // ghosts: the open sky
      s.threads = detail::resolveThreadCount(s.execution.threads);
      const BlockPlacement& b = s.placement;
      const Index3 scalarOffset = { b.begin[0] > 0 ? 1 : 0, b.begin[1] > 0 ? 1 : 0,
        b.begin[2] > 0 ? 1 : 0 };
      s.surfaceFound = initialiseDistance(s.scalars, scalarOffset, s.layout, s.parameters,
                         s.distance.data(), s.threads) > 0;
      s.fixed.build(s.distance.data(), s.layout.storage.count, s.threads);
      s.initialised = true;
      return Status::success();
    });
}

bool BlockSweeper::surfaceFound() const
{
  return this->Impl && this->Impl->surfaceFound;
}

void BlockSweeper::fillWithoutSurface()
{
  if (!this->initialised())
    return;
  State& s = *this->Impl;
  // Without a surface anywhere every voxel lies on the same side as the first own one.
  const bool allInside = s.distance[s.layout.index(0, 0, 0)] < 0.0f;
  detail::sweeping::fillWithoutSurface(s.layout, allInside, s.distance.data(), s.vis, s.maskCount);
}

Status BlockSweeper::runRound(int maxPasses, SweepReport* report)
{
  if (!this->initialised())
  {
    return Status::failure("runRound before a successful initialise()");
  }
  if (maxPasses < 1)
  {
    return Status::failure("a round needs at least one pass of the 8 sweeps");
  }
  State& s = *this->Impl;
  const double unit = sweepUnit(s.spacing);
  SweepParameters p = s.parameters;
  p.iterations = maxPasses;
  p.tolerance /= unit;
  SweepReport local;
  SweepReport& r = report ? *report : local;
  r.surfaceFound = s.surfaceFound;
  const int sweepThreads = static_cast<int>(std::min<std::int64_t>(s.threads, s.layout.size[2]));
  const Status status = catchOutOfMemory(kSweepBuffers,
    [&]
    {
      return runPasses(
        s.layout, p, s.distance.data(), s.fixed, s.vis, sweepThreads, s.execution, r);
    });
  r.lastChange *= unit;
  return status;
}

std::int64_t BlockSweeper::faceValueCount(int face) const
{
  if (!this->Impl)
    return 0;
  const State& s = *this->Impl;
  if (face < 0 || face >= kBlockFaces || !s.placement.hasNeighbour(face))
  {
    return 0;
  }
  const Index3& n = s.placement.size;
  const int axis = face / 2;
  return kFaceValues * n[0] * n[1] * n[2] / n[axis];
}

void BlockSweeper::exportFace(int face, float* buffer) const
{
  if (!this->initialised() || this->faceValueCount(face) == 0)
  {
    return;
  }
  const State& s = *this->Impl;
  const std::array<int, 4> octants = State::octantsMoving(face / 2, (face & 1) ? 1 : -1);
  s.forFaceVoxels(face, false,
    [&](std::int64_t i, std::int64_t k)
    {
      float* out = buffer + kFaceValues * k;
      out[0] = s.distance[i];
      for (int o = 0; o < 4; ++o)
        out[1 + o] = s.vis.field[octants[o]][i];
    });
}

double BlockSweeper::importFace(int face, const float* buffer)
{
  if (!this->initialised() || this->faceValueCount(face) == 0)
  {
    return 0.0;
  }
  State& s = *this->Impl;
  // The sweeps that read this ghost layer move away from it, into the block.
  const std::array<int, 4> octants = State::octantsMoving(face / 2, (face & 1) ? -1 : 1);
  const double unit = sweepUnit(s.spacing); // D is exchanged in sweep units
  double largest = 0.0;
  s.forFaceVoxels(face, true,
    [&](std::int64_t i, std::int64_t k)
    {
      const float* in = buffer + kFaceValues * k;
      largest = std::max(largest, changeOf(s.distance[i], in[0]) * unit);
      s.distance[i] = in[0];
      for (int o = 0; o < 4; ++o)
      {
        float& v = s.vis.field[octants[o]][i];
        largest = std::max(largest, changeOf(v, in[1 + o]));
        v = in[1 + o];
      }
    });
  return largest;
}

Status BlockSweeper::finish(const SweepOutput& output)
{
  if (!this->initialised())
  {
    return Status::failure("finish before a successful initialise()");
  }
  State& s = *this->Impl;
  const Status status = validateSweepParameters(
    s.spacing, s.parameters, output); // the volume was checked by initialise()
  if (!status.ok)
  {
    return status;
  }
  if (output.signedDistance)
  {
    const float unit = static_cast<float>(sweepUnit(s.spacing));
    const Index3& n = s.layout.size;
    for (std::int64_t z = 0; z < n[2]; ++z)
      for (std::int64_t y = 0; y < n[1]; ++y)
      {
        const float* row = s.distance.data() + s.layout.index(0, y, z);
        float* to = output.signedDistance + (z * n[1] + y) * n[0];
        for (std::int64_t x = 0; x < n[0]; ++x)
          to[x] = row[x] * unit; // sweep units to world units (exact: a power of two)
      }
  }
  return catchOutOfMemory(kSweepBuffers,
    [&]
    {
      return combine(s.layout, s.parameters, output, s.distance.data(), s.vis, s.maskCount,
        s.threads, s.execution);
    });
}

bool BlockSweeper::initialised() const
{
  return this->Impl && this->Impl->initialised;
}

} // namespace vao
