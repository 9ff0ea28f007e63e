// computeAmbientOcclusion end to end on random volumes: the exact references against an
// independent brute force, the separable estimators against docs/methods.md's formulas written
// again in ReferenceFormulas.h, applied to brute-force statistics, the properties of
// docs/methods.md, and decomposition invariance.
#include "ReferenceFormulas.h"
#include "TestVolumes.h"

#include "cpu/exact_reference/ExactReference.h"

#include <gtest/gtest.h>

#include <limits>
#include <random>

using namespace vaotest;

namespace
{

using vao::Method;

std::vector<float> openness(const vao::VolumeView& view, const vao::Region& region, Method method,
  vao::Radius r, vao::QueryMode query = vao::QueryMode::VoxelValue, double iso = 0,
  vao::ErfMode erf = vao::ErfMode::Exact, std::vector<float>* variance = nullptr)
{
  std::vector<float> out(region.voxelCount(), -1.0f);
  vao::AmbientOcclusionParameters p;
  p.method = method;
  p.radius = r;
  p.queryMode = query;
  p.isoValue = iso;
  p.erfMode = erf;
  vao::AmbientOcclusionOutput output{ out.data(), nullptr };
  if (variance)
  {
    variance->assign(region.voxelCount(), -1.0f);
    output.variance = variance->data();
  }
  const vao::Status status = vao::computeAmbientOcclusion(view, region, p, output);
  EXPECT_TRUE(status.ok) << status.message;
  return out;
}

template <class T>
void expectMatchesBruteForce(
  const std::vector<T>& v, const vao::Index3& dims, vao::Radius r, vao::QueryMode query, double iso)
{
  const auto view = viewOf(v, dims);
  const auto whole = vao::Region::whole(view);
  std::vector<float> variance;
  const auto exactBox = openness(view, whole, Method::ExactBox, r, query, iso);
  const auto exactSphere = openness(view, whole, Method::ExactSphere, r, query, iso);
  const auto cdf = openness(view, whole, Method::CdfReconstruction, r, query, iso);
  const auto gauss =
    openness(view, whole, Method::GaussianCdf, r, query, iso, vao::ErfMode::Exact, &variance);
  const auto winitzki =
    openness(view, whole, Method::GaussianCdf, r, query, iso, vao::ErfMode::Winitzki);
  const auto cheb = openness(view, whole, Method::Chebyshev, r, query, iso);
  std::int64_t k = 0, failures = 0;
  for (std::int64_t z = 0; z < dims[2]; ++z)
    for (std::int64_t y = 0; y < dims[1]; ++y)
      for (std::int64_t x = 0; x < dims[0]; ++x, ++k)
      {
        const double q = query == vao::QueryMode::IsoValue ? iso : double(v[k]);
        const auto ref = bruteForceStats(v, dims, r, x, y, z);
        const reference::Statistics s{ ref.mean, ref.variance, ref.minimum, ref.maximum };
        const double expected[] = { bruteForceOpenness(v, dims, r, x, y, z, q, false),
          bruteForceOpenness(v, dims, r, x, y, z, q, true), reference::cdfReconstruction(q, s),
          reference::gaussianCdf(q, s, false), reference::gaussianCdf(q, s, true),
          reference::chebyshev(q, s) };
        const float got[] = { exactBox[k], exactSphere[k], cdf[k], gauss[k], winitzki[k], cheb[k] };
        for (int m = 0; m < 6; ++m)
        {
          if (std::abs(got[m] - expected[m]) > 2e-6 && failures++ < 8)
            ADD_FAILURE() << "estimator " << m << " at (" << x << "," << y << "," << z
                          << "): " << got[m] << " vs " << expected[m];
          EXPECT_GE(got[m], 0.0f);
          EXPECT_LE(got[m], 1.0f);
        }
        if (std::abs(variance[k] - ref.variance) > 1e-6 * std::max(1.0, ref.variance) &&
          failures++ < 8)
          ADD_FAILURE() << "variance at " << k << ": " << variance[k] << " vs " << ref.variance;
        // Cantelli bound: Chebyshev never exceeds the exact box openness.
        if (cheb[k] > exactBox[k] + 1e-6f && failures++ < 8)
          ADD_FAILURE() << "Chebyshev above Exact Box at " << k;
      }
  EXPECT_EQ(failures, 0);
}

TEST(Openness, EveryMethodMatchesBruteForceOnRandomVolumes)
{
  const vao::Index3 dims = { 17, 11, 9 };
  const auto v8 = randomVolume<std::uint8_t>(dims, 0, 6, 21); // few values: ties and flat boxes
  const auto v16 = randomVolume<std::int16_t>(dims, -1024, 1600, 22);
  const auto vf = randomVolume<float>(dims, -1, 1, 23);
  // Above int16's range: CDF Reconstruction reads 16-bit rows as they are (raw rows).
  const auto vu16 = randomVolume<std::uint16_t>(dims, 40000, 65535, 24);
  for (int r = 0; r <= 4; ++r)
  {
    SCOPED_TRACE(r);
    expectMatchesBruteForce(v8, dims, { r, r, r }, vao::QueryMode::VoxelValue, 0);
    expectMatchesBruteForce(v16, dims, { r, r, r }, vao::QueryMode::VoxelValue, 0);
    expectMatchesBruteForce(vu16, dims, { r, r, r }, vao::QueryMode::VoxelValue, 0);
    expectMatchesBruteForce(vf, dims, { r, r, r }, vao::QueryMode::IsoValue, 0.25);
  }
  expectMatchesBruteForce(v16, dims, { 3, 1, 2 }, vao::QueryMode::IsoValue, 100.0);
  expectMatchesBruteForce(vu16, dims, { 2, 3, 1 }, vao::QueryMode::IsoValue, 52000.5);
  expectMatchesBruteForce(v8, dims, { 0, 4, 1 }, vao::QueryMode::VoxelValue, 0);
  expectMatchesBruteForce(v16, dims, { 30, 30, 30 }, vao::QueryMode::VoxelValue, 0);
}

TEST(Openness, ExactSphereIsTheInscribedEllipsoid)
{
  // A single bright voxel at the centre; count how many voxels of the sphere around a
  // dark corner voxel see it: none at the corner of the box, so box and sphere differ.
  const vao::Index3 dims = { 11, 11, 11 };
  std::vector<float> v(11 * 11 * 11, 0.0f);
  v[(5 * 11 + 5) * 11 + 5] = 1.0f;
  const auto view = viewOf(v, dims);
  const vao::Region corner{ { 2, 2, 2 }, { 1, 1, 1 } };
  const vao::Region face{ { 5, 5, 2 }, { 1, 1, 1 } };
  // The box of radius 3 around (2,2,2), clipped to 6^3 voxels, contains (5,5,5); the
  // sphere does not (distance 5.2 > 3).
  EXPECT_FLOAT_EQ(openness(view, corner, Method::ExactBox, { 3, 3, 3 })[0], 1.0f - 1.0f / 216);
  EXPECT_FLOAT_EQ(openness(view, corner, Method::ExactSphere, { 3, 3, 3 })[0], 1.0f);
  // Along the axis at distance 3 it is on the sphere's surface: included.
  const float sphere = openness(view, face, Method::ExactSphere, { 3, 3, 3 })[0];
  EXPECT_LT(sphere, 1.0f);
}

template <class T>
void expectPieceEqualsWhole(
  const std::vector<T>& v, const vao::Index3& dims, Method method, vao::Radius r, float tolerance)
{
  // A distributed run hands each rank its piece grown by the radius and clipped to the
  // whole extent; the piece's results must be those of the whole volume.
  const auto view = viewOf(v, dims);
  const auto whole = openness(view, vao::Region::whole(view), method, r);
  const vao::Region piece{ { 4, 0, 6 }, { 7, dims[1], 5 } };
  const vao::Index3 lo = { std::max<std::int64_t>(0, piece.begin[0] - r.x), 0,
    std::max<std::int64_t>(0, piece.begin[2] - r.z) };
  const vao::Index3 hi = { std::min(dims[0], piece.begin[0] + piece.size[0] + r.x), dims[1],
    std::min(dims[2], piece.begin[2] + piece.size[2] + r.z) };
  const vao::Index3 cropDims = { hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2] };
  std::vector<T> crop;
  for (std::int64_t z = lo[2]; z < hi[2]; ++z)
    for (std::int64_t y = lo[1]; y < hi[1]; ++y)
      for (std::int64_t x = lo[0]; x < hi[0]; ++x)
        crop.push_back(v[(z * dims[1] + y) * dims[0] + x]);
  const vao::Region inCrop{ { piece.begin[0] - lo[0], 0, piece.begin[2] - lo[2] }, piece.size };
  const auto part = openness(viewOf(crop, cropDims), inCrop, method, r);
  std::int64_t k = 0;
  for (std::int64_t z = piece.begin[2]; z < piece.begin[2] + piece.size[2]; ++z)
    for (std::int64_t y = 0; y < dims[1]; ++y)
      for (std::int64_t x = piece.begin[0]; x < piece.begin[0] + piece.size[0]; ++x, ++k)
        ASSERT_NEAR(part[k], whole[(z * dims[1] + y) * dims[0] + x], tolerance)
          << x << "," << y << "," << z;
}

TEST(Openness, APieceGrownByTheRadiusGivesTheWholeVolumesNumbers)
{
  const vao::Index3 dims = { 15, 9, 17 };
  const auto v16 = randomVolume<std::int16_t>(dims, -500, 500, 31);
  const auto vd = randomVolume<double>(dims, 1e6, 1e6 + 10, 32);
  for (auto method : { Method::CdfReconstruction, Method::GaussianCdf, Method::Chebyshev,
         Method::ExactBox, Method::ExactSphere })
  {
    expectPieceEqualsWhole(v16, dims, method, { 3, 2, 4 }, 0.0f);
    expectPieceEqualsWhole(vd, dims, method, { 2, 3, 3 }, 1e-6f);
  }
}

/// The moment methods on one component of three (a strided view) against the same values
/// stored alone, bit for bit, with each query: a voxel's own value must be read through
/// the stride too, and 16-bit voxels stored alone take CDF Reconstruction's raw rows, the
/// strided ones its rows of doubles.
template <class T>
void expectStridedComponentLikeContiguous(const std::vector<T>& v, const vao::Index3& dims)
{
  std::vector<T> interleaved(3 * v.size());
  for (std::size_t i = 0; i < v.size(); ++i)
  {
    interleaved[3 * i] = v[v.size() - 1 - i]; // other components hold other values
    interleaved[3 * i + 1] = v[i];
    interleaved[3 * i + 2] = v[(i * 7) % v.size()];
  }
  vao::VolumeView strided = viewOf(interleaved, dims, 3);
  strided.data = interleaved.data() + 1;
  const auto contiguous = viewOf(v, dims);
  for (const vao::Region region :
    { vao::Region::whole(contiguous), vao::Region{ { 2, 1, 1 }, { 19, 4, 3 } } })
    for (const vao::Radius r : { vao::Radius{ 1, 1, 1 }, vao::Radius{ 3, 2, 1 } })
      for (const Method method :
        { Method::CdfReconstruction, Method::GaussianCdf, Method::Chebyshev })
        for (const vao::QueryMode query :
          { vao::QueryMode::VoxelValue, vao::QueryMode::IsoValue, vao::QueryMode::SmoothedValue })
          EXPECT_EQ(openness(strided, region, method, r, query, 3.5),
            openness(contiguous, region, method, r, query, 3.5))
            << "method " << int(method) << ", query " << int(query) << ", radius " << r.x << ","
            << r.y << "," << r.z;
}

TEST(Openness, MomentMethodsReadEachVoxelsOwnValueThroughTheStride)
{
  const vao::Index3 dims = { 23, 6, 5 };
  expectStridedComponentLikeContiguous(randomVolume<std::int16_t>(dims, -1024, 1600, 31), dims);
  expectStridedComponentLikeContiguous(randomVolume<std::uint16_t>(dims, 0, 65535, 34), dims);
  expectStridedComponentLikeContiguous(randomVolume<std::uint8_t>(dims, 0, 255, 32), dims);
  expectStridedComponentLikeContiguous(randomVolume<float>(dims, -1, 1, 33), dims);
}

/// The exact references on every type, against the brute force's test double(v) <= q:
/// values at the type's ends, queries between two of its values, beyond its range and not
/// finite (the internal entry point takes any query), a sub-region, and a strided view.
template <class T>
void expectExactCountsLikeDoubles(const std::vector<T>& values, const std::vector<double>& queries)
{
  SCOPED_TRACE(sizeof(T));
  // Rows long enough for whole blocks of voxels whose windows are inside, and clipped ends.
  const vao::Index3 dims = { 45, 5, 4 };
  const std::int64_t n = dims[0] * dims[1] * dims[2];
  std::mt19937 rng(7);
  std::vector<T> v(n), interleaved(2 * n);
  for (std::int64_t i = 0; i < n; ++i)
  {
    v[i] = values[rng() % values.size()];
    interleaved[2 * i + 1] = v[i];
  }
  for (const vao::Region region :
    { vao::Region{ { 3, 1, 1 }, { 39, 3, 3 } }, vao::Region::whole(viewOf(v, dims)) })
  {
    std::vector<double> query(region.voxelCount());
    for (double& q : query)
      q = queries[rng() % queries.size()];
    for (const vao::Radius r : { vao::Radius{ 2, 1, 1 }, vao::Radius{ 4, 2, 0 },
           vao::Radius{ 7, 1, 1 }, vao::Radius{ 9, 1, 1 } })
      for (const Method method : { Method::ExactBox, Method::ExactSphere })
        for (const std::int64_t stride : { 1, 2 })
        {
          vao::AmbientOcclusionParameters p;
          p.method = method;
          p.radius = r;
          std::vector<float> got(region.voxelCount(), -1.0f);
          vao::VolumeView view = stride == 1 ? viewOf(v, dims) : viewOf(interleaved, dims, 2);
          view.data = stride == 1 ? v.data() : interleaved.data() + 1;
          ASSERT_TRUE(
            vao::detail::computeExactOpenness(view, region, p, query.data(), got.data(), {}).ok);
          std::int64_t k = 0, failures = 0;
          for (std::int64_t z = region.begin[2]; z < region.begin[2] + region.size[2]; ++z)
            for (std::int64_t y = region.begin[1]; y < region.begin[1] + region.size[1]; ++y)
              for (std::int64_t x = region.begin[0]; x < region.begin[0] + region.size[0]; ++x, ++k)
              {
                const auto expected = static_cast<float>(
                  bruteForceOpenness(v, dims, r, x, y, z, query[k], method == Method::ExactSphere));
                if (got[k] != expected && failures++ < 5)
                  ADD_FAILURE() << "stride " << stride << " at (" << x << "," << y << "," << z
                                << ") query " << query[k] << ": " << got[k] << " vs " << expected;
              }
        }
  }
}

TEST(Openness, ExactReferencesCountAsDoublesOnEveryType)
{
  const double nan = std::nan(""), inf = INFINITY;
  const std::vector<double> common = { nan, inf, -inf, 1e300, -1e300, 0.0, -0.0, 0.5, -0.5, 1.0,
    7.25 };
  auto with = [&](std::vector<double> extra)
  {
    extra.insert(extra.end(), common.begin(), common.end());
    return extra;
  };
  expectExactCountsLikeDoubles<std::int8_t>(
    { -128, 127, -1, 0, 1, 7 }, with({ -128, -128.5, 126.99, 127 }));
  expectExactCountsLikeDoubles<std::uint8_t>(
    { 0, 255, 1, 7, 128 }, with({ 254.5, 255, 255.5, 127.9 }));
  expectExactCountsLikeDoubles<std::int16_t>(
    { -32768, 32767, -1, 0, 7 }, with({ -32768.5, 32766.5, 32767 }));
  expectExactCountsLikeDoubles<std::uint16_t>({ 0, 65535, 1, 7 }, with({ 65534.5, 65535, 65536 }));
  expectExactCountsLikeDoubles<std::int32_t>({ INT32_MIN, INT32_MAX, -1, 0, 7 },
    with({ -2147483648.5, -2147483648.0, 2147483646.5, 2147483647.0 }));
  expectExactCountsLikeDoubles<std::uint32_t>(
    { 0, UINT32_MAX, 1, 7 }, with({ 4294967294.5, 4294967295.0 }));
  // 64-bit integers round on the way to double: 2^53 + 1 compares as 2^53, 2^64 - 1 as 2^64.
  const double two53 = 9007199254740992.0, two63 = 9223372036854775808.0;
  const std::int64_t big = (std::int64_t(1) << 53) + 1;
  expectExactCountsLikeDoubles<std::int64_t>(
    { INT64_MIN, INT64_MAX, big, big + 2, 0, 7 }, with({ two53, two53 + 2, -two63, two63 }));
  expectExactCountsLikeDoubles<std::uint64_t>(
    { 0, 7, std::uint64_t(big), UINT64_MAX }, with({ two53, 2 * two63, two63 }));
  // Floats: queries between two floats (0.1, 1e-46) and beyond the largest float.
  const double fmax = std::numeric_limits<float>::max(),
               tiny = std::numeric_limits<float>::denorm_min();
  expectExactCountsLikeDoubles<float>(
    { 0.1f, -0.1f, float(fmax), float(-fmax), float(tiny), 0, INFINITY, -INFINITY, NAN },
    with({ 0.1, static_cast<double>(0.1f), -0.1, 1e-46, tiny, 2 * fmax, fmax, -fmax, -2 * fmax }));
  expectExactCountsLikeDoubles<double>({ 0.1, -0.1, 1e308, -1e308, 5e-324, inf, -inf, nan },
    with({ 0.1, std::nextafter(0.1, 1.0), 1e308, 5e-324, 1e-320 }));
}

TEST(Openness, RejectsNonFiniteIsoValue)
{
  const vao::Index3 dims = { 4, 4, 4 };
  const auto v = randomVolume<float>(dims, 0, 1, 1);
  std::vector<float> out(64);
  vao::AmbientOcclusionParameters p;
  p.radius = { 1, 1, 1 };
  p.queryMode = vao::QueryMode::IsoValue;
  p.isoValue = std::nan("");
  const auto status = vao::computeAmbientOcclusion(
    viewOf(v, dims), vao::Region::whole(viewOf(v, dims)), p, { out.data(), nullptr });
  EXPECT_FALSE(status.ok);
}

TEST(Openness, CountsNonFiniteVoxels)
{
  const vao::Index3 dims = { 4, 4, 4 };
  auto v = randomVolume<float>(dims, 0, 1, 1);
  EXPECT_EQ(vao::countNonFinite(viewOf(v, dims)), 0);
  v[17] = std::nanf("");
  v[40] = INFINITY;
  std::int64_t first = -1;
  EXPECT_EQ(vao::countNonFinite(viewOf(v, dims), &first), 2);
  EXPECT_EQ(first, 17);
  const auto range = vao::valueRange(viewOf(randomVolume<std::int16_t>(dims, -5, 7, 2), dims));
  EXPECT_GE(range[0], -5);
  EXPECT_LE(range[1], 7);
}

} // namespace
