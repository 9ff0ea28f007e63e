// A piece of a data set, given the data set's moment basis (vao::MomentBasis: the shift of
// the double sums and the data's range), gets the whole volume's openness, also in nearly
// flat boxes whose variance lies near the rounding bound: there the bound decides, and a
// piece's own basis (its own sampled mean and range) moves it (by 0.38 in this scene).
// What remains is the rounding of the running sums, which start where a piece (or a
// thread's chunk of slices) starts: as large as between two thread counts on the whole.
//
// The sampled shift's reference is written here: the mean of every max(1, n / 65536)-th
// voxel of the data set in x-fastest order.
#include "TestVolumes.h"
#include "vao/AmbientOcclusion.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

namespace
{

using vaotest::viewOf;

constexpr std::int64_t kNx = 48, kNy = 44, kNz = 40;

/// Blobs over a rippled floor that fade to ~1e-11 far from them: the far corner's boxes
/// have variances around 1e-12, near the bound of sums taken about values up to 2.4.
std::vector<float> fadingScene()
{
  std::vector<float> v(static_cast<std::size_t>(kNx * kNy * kNz));
  for (std::int64_t z = 0; z < kNz; ++z)
    for (std::int64_t y = 0; y < kNy; ++y)
      for (std::int64_t x = 0; x < kNx; ++x)
      {
        const double floorZ = 6.0 + std::sin(x / 4.0) * std::cos(y / 5.0);
        double s = 2.0 * std::exp(-(z - floorZ) * (z - floorZ) / 8.0);
        for (int k = 0; k < 6; ++k)
        {
          const double a = k * M_PI / 3.0 + 0.3;
          const double cx = kNx / 2.0 + 12.0 * std::cos(a), cy = kNy / 2.0 + 12.0 * std::sin(a);
          const double cz = 18.0 + 3.0 * std::sin(a + 0.75), r = 5.0 + 0.8 * std::sin(k + 0.75);
          const double d2 = (x - cx) * (x - cx) + (y - cy) * (y - cy) + (z - cz) * (z - cz);
          s += 2.0 * std::exp(-d2 / (2.0 * r * r));
        }
        v[static_cast<std::size_t>((z * kNy + y) * kNx + x)] = static_cast<float>(s);
      }
  return v;
}

/// [begin, begin + size) per axis.
struct Box
{
  vao::Index3 begin, size;
};

std::vector<float> crop(const std::vector<float>& v, const Box& b)
{
  std::vector<float> out;
  for (std::int64_t z = b.begin[2]; z < b.begin[2] + b.size[2]; ++z)
    for (std::int64_t y = b.begin[1]; y < b.begin[1] + b.size[1]; ++y)
      for (std::int64_t x = b.begin[0]; x < b.begin[0] + b.size[0]; ++x)
        out.push_back(v[static_cast<std::size_t>((z * kNy + y) * kNx + x)]);
  return out;
}

/// The whole data set's basis, its shift summed from pieces that tile it (two z slabs
/// and an x cut of the upper one).
vao::MomentBasis basisFromPieces(const std::vector<float>& v)
{
  const vao::Index3 whole{ kNx, kNy, kNz };
  const Box tiles[] = { { { 0, 0, 0 }, { kNx, kNy, 17 } }, { { 0, 0, 17 }, { 29, kNy, kNz - 17 } },
    { { 29, 0, 17 }, { kNx - 29, kNy, kNz - 17 } } };
  double sum = 0.0;
  std::int64_t count = 0;
  vao::MomentBasis basis;
  basis.lowest = 1e300;
  basis.highest = -1e300;
  for (const Box& t : tiles)
  {
    const std::vector<float> piece = crop(v, t);
    const vao::VolumeView view = viewOf(piece, t.size);
    const vao::ShiftSamples s =
      vao::momentShiftSamples(view, vao::Region::whole(view), t.begin, whole);
    sum += s.sum;
    count += s.count;
    const auto range = vao::valueRange(view);
    basis.lowest = std::min(basis.lowest, range[0]);
    basis.highest = std::max(basis.highest, range[1]);
  }
  basis.shift = sum / count;
  return basis;
}

TEST(MomentBasis, ShiftSamplesOfTilingPiecesAreTheWholeVolumesSamples)
{
  // 70 x 60 x 50 voxels: a step of 3, so pieces start off the sampling grid.
  const vao::Index3 whole{ 70, 60, 50 };
  std::vector<double> v(static_cast<std::size_t>(whole[0] * whole[1] * whole[2]));
  for (std::size_t i = 0; i < v.size(); ++i)
    v[i] = std::sin(0.001 * static_cast<double>(i)) * 100.0 + static_cast<double>(i % 7);
  const std::int64_t n = static_cast<std::int64_t>(v.size()),
                     step = std::max<std::int64_t>(1, n / 65536);
  double referenceSum = 0.0;
  std::int64_t referenceCount = 0;
  for (std::int64_t i = 0; i < n; i += step, ++referenceCount)
    referenceSum += v[static_cast<std::size_t>(i)];
  ASSERT_EQ(step, 3);

  // Pieces of unequal size on every axis; each holds a margin, and its region is its own.
  double sum = 0.0;
  std::int64_t count = 0;
  const std::int64_t cuts[3][3] = { { 0, 23, 70 }, { 0, 31, 60 }, { 0, 17, 50 } };
  for (int i = 0; i < 2; ++i)
    for (int j = 0; j < 2; ++j)
      for (int k = 0; k < 2; ++k)
      {
        const vao::Index3 lo{ cuts[0][i], cuts[1][j], cuts[2][k] };
        const vao::Index3 hi{ cuts[0][i + 1], cuts[1][j + 1], cuts[2][k + 1] };
        // The block the piece holds: its region plus up to 2 voxels each side.
        vao::Index3 from, size;
        for (int a = 0; a < 3; ++a)
        {
          from[a] = std::max<std::int64_t>(0, lo[a] - 2);
          size[a] = std::min(whole[a], hi[a] + 2) - from[a];
        }
        std::vector<double> block;
        for (std::int64_t z = from[2]; z < from[2] + size[2]; ++z)
          for (std::int64_t y = from[1]; y < from[1] + size[1]; ++y)
            for (std::int64_t x = from[0]; x < from[0] + size[0]; ++x)
              block.push_back(v[static_cast<std::size_t>((z * whole[1] + y) * whole[0] + x)]);
        const vao::Region region{ { lo[0] - from[0], lo[1] - from[1], lo[2] - from[2] },
          { hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2] } };
        const vao::ShiftSamples s =
          vao::momentShiftSamples(viewOf(block, size), region, from, whole);
        sum += s.sum;
        count += s.count;
      }
  EXPECT_EQ(count, referenceCount);
  EXPECT_NEAR(sum, referenceSum, 1e-9 * std::abs(referenceSum));
}

TEST(MomentBasis, PiecesWithTheDataSetsBasisGetTheWholeVolumesOpenness)
{
  const std::vector<float> v = fadingScene();
  const vao::Index3 whole{ kNx, kNy, kNz };
  const vao::MomentBasis basis = basisFromPieces(v);
  const int r = 4;
  vao::Execution single, several;
  single.threads = 1;
  several.threads = 5;
  // Pieces as ranks hold them: a piece's region and its radius around it.
  const Box regions[] = { { { 0, 0, 0 }, { 24, kNy, kNz } }, { { 24, 0, 0 }, { 24, kNy, kNz } },
    { { 0, 0, 20 }, { kNx, kNy, 20 } }, { { 30, 25, 25 }, { 18, 19, 15 } } };
  for (const vao::Method method :
    { vao::Method::GaussianCdf, vao::Method::Chebyshev, vao::Method::CdfReconstruction })
  {
    vao::AmbientOcclusionParameters p;
    p.method = method;
    p.radius = { r, r, r };
    std::vector<float> wholeOpenness(v.size()), wholeVariance(v.size()), otherThreads(v.size());
    ASSERT_TRUE(vao::computeAmbientOcclusion(viewOf(v, whole), vao::Region::whole(viewOf(v, whole)),
      p, { wholeOpenness.data(), wholeVariance.data() }, single)
                  .ok);
    ASSERT_TRUE(vao::computeAmbientOcclusion(
      viewOf(v, whole), vao::Region::whole(viewOf(v, whole)), p, { otherThreads.data() }, several)
                  .ok);
    double threadSpread = 0.0;
    for (std::size_t i = 0; i < v.size(); ++i)
      threadSpread = std::max(threadSpread, std::abs(double(otherThreads[i]) - wholeOpenness[i]));
    const double tolerance = std::max(1e-6, 4.0 * threadSpread);
    double ownBasisWorst = 0.0;
    for (const Box& region : regions)
    {
      Box held;
      for (int a = 0; a < 3; ++a)
      {
        held.begin[a] = std::max<std::int64_t>(0, region.begin[a] - r);
        held.size[a] = std::min(whole[a], region.begin[a] + region.size[a] + r) - held.begin[a];
      }
      const std::vector<float> piece = crop(v, held);
      const vao::Region inPiece{ { region.begin[0] - held.begin[0], region.begin[1] - held.begin[1],
                                   region.begin[2] - held.begin[2] },
        region.size };
      std::vector<float> openness(static_cast<std::size_t>(inPiece.voxelCount())),
        variance(openness.size()), ownOpenness(openness.size());
      vao::AmbientOcclusionParameters withBasis = p;
      withBasis.momentBasis = basis;
      ASSERT_TRUE(vao::computeAmbientOcclusion(
        viewOf(piece, held.size), inPiece, withBasis, { openness.data(), variance.data() })
                    .ok);
      ASSERT_TRUE(
        vao::computeAmbientOcclusion(viewOf(piece, held.size), inPiece, p, { ownOpenness.data() })
          .ok);
      double worst = 0.0, worstVariance = 0.0;
      std::size_t i = 0;
      for (std::int64_t z = region.begin[2]; z < region.begin[2] + region.size[2]; ++z)
        for (std::int64_t y = region.begin[1]; y < region.begin[1] + region.size[1]; ++y)
          for (std::int64_t x = region.begin[0]; x < region.begin[0] + region.size[0]; ++x, ++i)
          {
            const std::size_t w = static_cast<std::size_t>((z * kNy + y) * kNx + x);
            worst = std::max(worst, std::abs(double(openness[i]) - wholeOpenness[w]));
            worstVariance = std::max(worstVariance,
              std::abs(double(variance[i]) - wholeVariance[w]) /
                std::max(1e-30, double(wholeVariance[w])));
            ownBasisWorst =
              std::max(ownBasisWorst, std::abs(double(ownOpenness[i]) - wholeOpenness[w]));
          }
      EXPECT_LE(worst, tolerance) << "method " << static_cast<int>(method) << " region at "
                                  << region.begin[0] << ", " << region.begin[1] << ", "
                                  << region.begin[2];
      EXPECT_LE(worstVariance, 1e-2) << "method " << static_cast<int>(method);
    }
    // The premise: with its own basis, some piece's nearly flat boxes answer otherwise.
    if (method == vao::Method::GaussianCdf)
      EXPECT_GT(ownBasisWorst, 0.1);
  }
}

} // namespace
