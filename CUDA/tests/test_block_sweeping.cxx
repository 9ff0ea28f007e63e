// Occlusion sweeping on the blocks of a split volume (BlockSweeper), the MPI exchange
// emulated in memory: every block sweeps, exports its faces, imports its neighbours'
// faces, until no ghost value changes by more than the tolerance. The assembled result is
// compared with the converged serial sweeping of the whole volume.
#include "SweepScene.h"
#include "SweepTestSupport.h"
#include "vao/BlockSweeping.h"

#include <gtest/gtest.h>

#include <cstdlib>
#include <iostream>
#include <limits>
#include <memory>

using namespace vaotest;

namespace
{

// ---------------------------------------------------------------------------------------
// The emulated ranks

using Blocks = std::array<int, 3>; // blocks per axis

struct Distributed
{
  vao::Status status;
  std::vector<float> distance, occlusion, octants;
  std::vector<bool> blockSurfaceFound;
  int rounds = 0;          // rounds of sweeps run
  double lastChange = 0.0; // largest ghost change of the last exchange
};

struct Emulation
{
  bool exchange = true; // false: one round, faces never imported
  int maxRounds = 100;
};

/// Block b of k along an axis of n voxels: [n b / k, n (b + 1) / k).
std::int64_t cut(std::int64_t n, int k, int b)
{
  return n * b / k;
}

/// The scalars of a block with its ghost layer, copied out of the whole volume.
std::vector<float> blockScalars(const std::vector<float>& values, const vao::BlockPlacement& b)
{
  const vao::Index3 dims = b.scalarDims();
  const vao::Index3 first = { b.begin[0] - b.hasNeighbour(0), b.begin[1] - b.hasNeighbour(2),
    b.begin[2] - b.hasNeighbour(4) };
  std::vector<float> out;
  out.reserve(static_cast<std::size_t>(dims[0] * dims[1] * dims[2]));
  for (std::int64_t z = 0; z < dims[2]; ++z)
    for (std::int64_t y = 0; y < dims[1]; ++y)
      for (std::int64_t x = 0; x < dims[0]; ++x)
        out.push_back(
          values[((first[2] + z) * b.whole[1] + first[1] + y) * b.whole[0] + first[0] + x]);
  return out;
}

using Sweepers = std::vector<std::unique_ptr<vao::BlockSweeper>>;

/// Initialises the blocks and runs rounds of sweeps and face exchanges as the ranks would
/// (neighbours[b][face]: the block across the face, or -1) until no ghost value changes by
/// more than the tolerance.
void runRounds(Sweepers& sweepers, const std::vector<std::array<int, 6>>& neighbours,
  const vao::SweepParameters& p, const Emulation& emulation, Distributed& result)
{
  const int count = static_cast<int>(sweepers.size());
  bool anySurface = false;
  for (auto& s : sweepers)
  {
    result.status = s->initialise();
    if (!result.status.ok)
      return;
    result.blockSurfaceFound.push_back(s->surfaceFound());
    anySurface = anySurface || s->surfaceFound();
  }
  if (!anySurface)
  {
    for (auto& s : sweepers)
      s->fillWithoutSurface();
  }
  else
  {
    std::vector<std::array<std::vector<float>, 6>> sent(count);
    for (int round = 1; round <= emulation.maxRounds; ++round)
    {
      for (auto& s : sweepers)
      {
        result.status = s->runRound(p.iterations);
        if (!result.status.ok)
          return;
      }
      result.rounds = round;
      if (!emulation.exchange)
        break;
      for (int b = 0; b < count; ++b)
        for (int face = 0; face < vao::kBlockFaces; ++face)
        {
          sent[b][face].resize(static_cast<std::size_t>(sweepers[b]->faceValueCount(face)));
          sweepers[b]->exportFace(face, sent[b][face].data());
        }
      double change = 0.0; // the max over the ranks
      for (int b = 0; b < count; ++b)
        for (int face = 0; face < vao::kBlockFaces; ++face)
          if (neighbours[b][face] >= 0)
          {
            const std::vector<float>& in = sent[neighbours[b][face]][vao::oppositeFace(face)];
            EXPECT_EQ(static_cast<std::int64_t>(in.size()), sweepers[b]->faceValueCount(face));
            change = std::max(change, sweepers[b]->importFace(face, in.data()));
          }
      result.lastChange = change;
      if (change <= p.tolerance)
        break;
    }
  }
}

/// The blocks' outputs assembled into whole-volume arrays.
void assembleOutputs(Sweepers& sweepers, const std::vector<vao::BlockPlacement>& placements,
  const vao::Index3& dims, Distributed& result)
{
  const int count = static_cast<int>(sweepers.size());
  const std::int64_t n = dims[0] * dims[1] * dims[2];
  result.distance.assign(n, -7.0f);
  result.occlusion.assign(n, -7.0f);
  result.octants.assign(8 * n, -7.0f);
  for (int b = 0; b < count; ++b)
  {
    const vao::BlockPlacement& placement = placements[b];
    const vao::Index3& size = placement.size;
    const std::int64_t m = size[0] * size[1] * size[2];
    std::vector<float> d(m), a(m), v(8 * m);
    result.status = sweepers[b]->finish({ d.data(), a.data(), v.data() });
    if (!result.status.ok)
      return;
    std::int64_t k = 0;
    for (std::int64_t z = 0; z < size[2]; ++z)
      for (std::int64_t y = 0; y < size[1]; ++y)
        for (std::int64_t x = 0; x < size[0]; ++x, ++k)
        {
          const std::int64_t i =
            ((placement.begin[2] + z) * dims[1] + placement.begin[1] + y) * dims[0] +
            placement.begin[0] + x;
          result.distance[i] = d[k];
          result.occlusion[i] = a[k];
          std::copy(v.begin() + 8 * k, v.begin() + 8 * k + 8, result.octants.begin() + 8 * i);
        }
  }
}

/// Sweeps the volume split into blocks[0] x blocks[1] x blocks[2] blocks, each with
/// p.iterations passes per round at most, and assembles the outputs.
Distributed sweepInBlocks(const std::vector<float>& values, const vao::Index3& dims,
  const Spacing& h, const Blocks& blocks, const vao::SweepParameters& p, bool withOutputs = true,
  const Emulation& emulation = {})
{
  Distributed result;
  const int count = blocks[0] * blocks[1] * blocks[2];
  auto blockIndex = [&](int bx, int by, int bz) { return (bz * blocks[1] + by) * blocks[0] + bx; };
  std::vector<vao::BlockPlacement> placements(count);
  std::vector<std::array<int, 6>> neighbours(count);
  std::vector<std::vector<float>> scalars(count);
  Sweepers sweepers;
  for (int bz = 0; bz < blocks[2]; ++bz)
    for (int by = 0; by < blocks[1]; ++by)
      for (int bx = 0; bx < blocks[0]; ++bx)
      {
        const int b = blockIndex(bx, by, bz);
        const int position[3] = { bx, by, bz };
        vao::BlockPlacement& placement = placements[b];
        placement.whole = dims;
        for (int a = 0; a < 3; ++a)
        {
          placement.begin[a] = cut(dims[a], blocks[a], position[a]);
          placement.size[a] = cut(dims[a], blocks[a], position[a] + 1) - placement.begin[a];
        }
        for (int face = 0; face < vao::kBlockFaces; ++face)
        {
          int q[3] = { bx, by, bz };
          q[face / 2] += (face & 1) ? 1 : -1;
          neighbours[b][face] = placement.hasNeighbour(face) ? blockIndex(q[0], q[1], q[2]) : -1;
        }
        scalars[b] = blockScalars(values, placement);
        sweepers.push_back(std::make_unique<vao::BlockSweeper>(
          viewOf(scalars[b], placement.scalarDims()), placement, h, p));
      }

  runRounds(sweepers, neighbours, p, emulation, result);
  if (result.status.ok && withOutputs)
    assembleOutputs(sweepers, placements, dims, result);
  return result;
}

Distributed sweepInBlocks(const Scene& scene, const Blocks& blocks, const vao::SweepParameters& p,
  const Emulation& emulation = {})
{
  return sweepInBlocks(scene.values, scene.dims, scene.spacing, blocks, p, true, emulation);
}

/// Serial and distributed runs converge to the same fixed point.
vao::SweepParameters convergedTo(double tolerance)
{
  return withIterations(50, tolerance);
}

std::string name(const Blocks& b)
{
  return std::to_string(b[0]) + "x" + std::to_string(b[1]) + "x" + std::to_string(b[2]);
}

/// Largest |a - b| over the finite pairs; infinity where only one side is finite.
double largestDistanceDifference(const std::vector<float>& a, const std::vector<float>& b)
{
  double worst = 0;
  for (std::size_t i = 0; i < a.size(); ++i)
    if (a[i] != b[i])
    {
      const double d = std::abs(double(a[i]) - b[i]);
      worst = std::max(worst, std::isfinite(d) ? d : std::numeric_limits<double>::infinity());
    }
  return worst;
}

// ---------------------------------------------------------------------------------------
// Against the serial result

TEST(BlockSweeping, EverySplitMatchesTheConvergedSerialResult)
{
  const Scene scene = makeScene({ 29, 23, 31 }, { 1, 0.9, 1.2 }, spheresAndBox());
  const double hMin = 0.9;
  const std::vector<Blocks> splits = { { 2, 1, 1 }, { 3, 1, 1 }, { 4, 1, 1 }, { 1, 2, 1 },
    { 1, 3, 1 }, { 1, 4, 1 }, { 1, 1, 2 }, { 1, 1, 3 }, { 1, 1, 4 }, { 2, 2, 1 }, { 2, 2, 2 } };
  struct Variant
  {
    bool geometry;
    double opacity;
  };
  double worstD = 0, worstA = 0, worstV = 0;
  for (const Variant variant :
    { Variant{ false, 1.0 }, Variant{ true, 1.0 }, Variant{ false, 0.5 }, Variant{ true, 0.5 } })
  {
    vao::SweepParameters p = convergedTo(1e-6);
    p.useGeometryTerm = variant.geometry;
    p.opacity = variant.opacity;
    const Result serial = sweep(scene.view(), scene.spacing, p);
    ASSERT_TRUE(serial.status.ok) << serial.status.message;
    ASSERT_LT(serial.report.passes, p.iterations);
    std::string rounds;
    for (const Blocks& blocks : splits)
    {
      SCOPED_TRACE(name(blocks) + (variant.geometry ? ", geometry term" : ", mean") + ", opacity " +
        std::to_string(variant.opacity));
      const Distributed d = sweepInBlocks(scene, blocks, p);
      ASSERT_TRUE(d.status.ok) << d.status.message;
      EXPECT_LE(d.lastChange, p.tolerance) << "not converged in " << d.rounds << " rounds";
      const double dD = largestDistanceDifference(d.distance, serial.distance);
      const double dA = largestDifference(d.occlusion, serial.occlusion);
      const double dV = largestDifference(d.octants, serial.octants);
      EXPECT_LE(dD, 1e-5 * hMin);
      EXPECT_LE(dA, 1e-5);
      EXPECT_LE(dV, 1e-5);
      worstD = std::max(worstD, dD);
      worstA = std::max(worstA, dA);
      worstV = std::max(worstV, dV);
      // V crosses one block per round, along chains of up to `chain` blocks; D needs more
      // where its characteristics cross a face and come back, and then a tail of changes
      // of an ulp or two (the tolerance is below the ulp of D > 8).
      const int chain = blocks[0] + blocks[1] + blocks[2] - 2;
      EXPECT_LE(d.rounds, 2 * chain + 2);
      rounds += " " + name(blocks) + ":" + std::to_string(d.rounds);
    }
    std::cout << "[ rounds   ] geometry " << variant.geometry << " opacity " << variant.opacity
              << ":" << rounds << "\n";
  }
  std::cout << "[ vs serial] max |dD| " << worstD << ", |dA| " << worstA << ", |dV| " << worstV
            << "\n";
}

/// The blocks give the serial result bit for bit, after `rounds` rounds.
void expectSerialBits(const Scene& scene, const Blocks& blocks, int rounds)
{
  vao::SweepParameters p = convergedTo(1e-6);
  p.useGeometryTerm = true;
  const Result serial = sweep(scene.view(), scene.spacing, p);
  const Distributed d = sweepInBlocks(scene, blocks, p);
  ASSERT_TRUE(d.status.ok) << d.status.message;
  EXPECT_EQ(d.rounds, rounds);
  EXPECT_EQ(d.distance, serial.distance);
  EXPECT_EQ(d.occlusion, serial.occlusion);
  EXPECT_EQ(d.octants, serial.octants);
}

TEST(BlockSweeping, OneBlockIsTheSerialResultBitForBit)
{
  expectSerialBits(makeScene({ 19, 17, 21 }, { 1, 1.2, 0.9 }, spheresAndBox()), { 1, 1, 1 }, 1);
}

// ---------------------------------------------------------------------------------------
// The exchange carries the shadow and the distance

TEST(BlockSweeping, ASlabInOneBlockShadowsTheBlockBelowOnlyThroughTheExchange)
{
  // A roof over the whole x-y extent, in the upper of two z-blocks; the lower block has
  // no surface of its own. Under the roof the light from above (octants 4..7) enters only
  // from the open sides of the volume.
  const vao::Index3 dims = { 16, 14, 24 };
  const Scene scene = makeScene(dims, { 1, 1, 1 }, box(7.5, 6.5, 18.2, 20, 20, 1.6));
  const vao::SweepParameters p = convergedTo(1e-6);
  const Result serial = sweep(scene.view(), scene.spacing, p);
  const Distributed exchanged = sweepInBlocks(scene, { 1, 1, 2 }, p);
  Emulation isolated;
  isolated.exchange = false;
  const Distributed alone = sweepInBlocks(scene, { 1, 1, 2 }, p, isolated);
  ASSERT_TRUE(exchanged.status.ok && alone.status.ok);
  EXPECT_EQ(exchanged.blockSurfaceFound, (std::vector<bool>{ false, true }));

  double serialDarkest = 1.0, difference = 0.0, differenceAlone = 0.0;
  for (std::int64_t z = 0; z < dims[2] / 2; ++z) // the lower block
    for (std::int64_t y = 0; y < dims[1]; ++y)
      for (std::int64_t x = 0; x < dims[0]; ++x)
      {
        const std::int64_t i = scene.index(x, y, z);
        for (int s = 4; s < 8; ++s)
        {
          const double v = serial.octant(i, s);
          serialDarkest = std::min(serialDarkest, v);
          difference = std::max(difference, std::abs(exchanged.octants[8 * i + s] - v));
          differenceAlone = std::max(differenceAlone, std::abs(alone.octants[8 * i + s] - v));
          EXPECT_EQ(alone.octants[8 * i + s], 1.0f); // open sky without the exchange
        }
        EXPECT_TRUE(std::isfinite(exchanged.distance[i]));
        EXPECT_FALSE(std::isfinite(alone.distance[i])); // no surface of its own
      }
  EXPECT_LT(serialDarkest, 0.1); // the roof shadows the centre of the lower block
  EXPECT_LE(difference, 1e-5);
  EXPECT_GT(differenceAlone, 0.9);
  EXPECT_LE(largestDistanceDifference(exchanged.distance, serial.distance), 1e-5);
}

TEST(BlockSweeping, BlocksWithoutASurfaceOfTheirOwnGetTheirDistanceFromNeighbours)
{
  // A sphere in the first of four x-blocks: the other three have no crossing edge.
  const Scene scene = makeScene({ 32, 13, 15 }, { 1.1, 1, 0.9 }, sphere(3.5, 6.1, 6.8, 2.6));
  vao::SweepParameters p = convergedTo(1e-6);
  p.useGeometryTerm = true;
  const Result serial = sweep(scene.view(), scene.spacing, p);
  const Distributed d = sweepInBlocks(scene, { 4, 1, 1 }, p);
  ASSERT_TRUE(d.status.ok) << d.status.message;
  EXPECT_EQ(d.blockSurfaceFound, (std::vector<bool>{ true, false, false, false }));
  EXPECT_LE(largestDistanceDifference(d.distance, serial.distance), 1e-5);
  EXPECT_LE(largestDifference(d.occlusion, serial.occlusion), 1e-5);
  EXPECT_LE(largestDifference(d.octants, serial.octants), 1e-5);
  std::cout << "[ rounds   ] sphere in 1 of 4 x-blocks: " << d.rounds << "\n";
}

TEST(BlockSweeping, WithoutAnySurfaceEveryBlockFillsAsTheSerialCode)
{
  for (const float value : { -1.0f, 1.0f }) // all outside, all inside (v > 0)
  {
    Scene scene = makeScene({ 9, 8, 10 }, { 1, 1.5, 0.8 }, sphere(0, 0, 0, 0));
    std::fill(scene.values.begin(), scene.values.end(), value);
    expectSerialBits(scene, { 2, 2, 1 }, 0);
  }
}

TEST(BlockSweeping, RejectsScalarsWithoutTheGhostLayer)
{
  const Scene scene = makeScene({ 10, 9, 8 }, { 1, 1, 1 }, sphere(5, 4, 4, 2));
  vao::BlockPlacement placement;
  placement.whole = scene.dims;
  placement.begin = { 5, 0, 0 };
  placement.size = { 5, 9, 8 };
  // The own voxels only: the -x ghost layer of scalars is missing.
  std::vector<float> own;
  for (std::int64_t z = 0; z < 8; ++z)
    for (std::int64_t y = 0; y < 9; ++y)
      for (std::int64_t x = 5; x < 10; ++x)
        own.push_back(scene.values[scene.index(x, y, z)]);
  vao::BlockSweeper block(viewOf(own, placement.size), placement, scene.spacing, {});
  const vao::Status status = block.initialise();
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.message.find("ghost layer"), std::string::npos) << status.message;
  EXPECT_FALSE(block.runRound(1).ok);
}

// ---------------------------------------------------------------------------------------
// Rounds on the generated benchmark scene

/// Rounds for the generated scene of nx^3 voxels (SweepScene.h) in 2, 3 and 4 z-slabs,
/// with the largest differences from serial. VAO_BLOCK_ROUNDS_SIZE sets nx (default 64).
TEST(BlockSweepingRounds, GeneratedSceneInZSlabs)
{
  const char* size = std::getenv("VAO_BLOCK_ROUNDS_SIZE");
  const std::int64_t n = size ? std::atoll(size) : 64;
  const vao::Index3 dims = { n, n, n };
  const std::vector<float> values =
    SceneVolume(static_cast<int>(n), static_cast<int>(n), static_cast<int>(n));
  vao::VolumeView view = viewOf(values, dims);
  vao::SweepParameters p = convergedTo(1e-6);
  p.isoValue = 0.5;
  const Result serial = sweep(view, { 1, 1, 1 }, p);
  ASSERT_TRUE(serial.status.ok);
  for (int slabs : { 2, 3, 4 })
  {
    const Distributed d = sweepInBlocks(values, dims, { 1, 1, 1 }, { 1, 1, slabs }, p);
    ASSERT_TRUE(d.status.ok) << d.status.message;
    const double dD = largestDistanceDifference(d.distance, serial.distance);
    const double dDRelative = largestDifference(d.distance, serial.distance, true);
    const double dA = largestDifference(d.occlusion, serial.occlusion);
    const double dV = largestDifference(d.octants, serial.octants);
    std::cout << "[ rounds   ] " << n << "^3 scene, " << slabs << " z-slabs: " << d.rounds
              << " rounds (serial " << serial.report.passes << " passes); max |dD| " << dD
              << " (relative " << dDRelative << "), |dA| " << dA << ", |dV| " << dV << "\n";
    // D up to ~0.7 n voxels: a few ulps of it, from other rounding paths to the same
    // fixed point (measured relative 5e-7 at 64^3, 9.5e-7 at 256^3; V and A identical).
    EXPECT_LE(dDRelative, 2e-6);
    EXPECT_LE(dA, 1e-5);
    EXPECT_LE(dV, 1e-5);
  }
}

} // namespace
