// The smoothed query (docs/methods.md section 9) against a brute force of its definition: a 3-D sum
// of Gaussian weights over the clipped window, renormalised, fed to every method.
#include "ReferenceFormulas.h"
#include "TestVolumes.h"

#include "vao/HistogramCdf.h"

#include <gtest/gtest.h>

using namespace vaotest;

namespace
{

/// q(x) = sum g(y - x) v(y) / sum g(y - x) over the voxels y of the volume with
/// |y_i - x_i| <= ceil(3 sigma), g(d) = prod exp(-d_i^2 / (2 sigma^2)).
template <class T>
long double referenceQuery(const std::vector<T>& v, const vao::Index3& d, double sigma,
  std::int64_t x, std::int64_t y, std::int64_t z)
{
  const auto w = static_cast<std::int64_t>(std::ceil(3.0 * sigma));
  long double num = 0, den = 0;
  for (std::int64_t k = z - w; k <= z + w; ++k)
    for (std::int64_t j = y - w; j <= y + w; ++j)
      for (std::int64_t i = x - w; i <= x + w; ++i)
      {
        if (i < 0 || j < 0 || k < 0 || i >= d[0] || j >= d[1] || k >= d[2])
          continue;
        const long double d2 = (long double)(i - x) * (i - x) + (long double)(j - y) * (j - y) +
          (long double)(k - z) * (k - z);
        const long double g = std::exp(-d2 / (2.0L * sigma * sigma));
        num += g * static_cast<long double>(v[(k * d[1] + j) * d[0] + i]);
        den += g;
      }
  return num / den;
}

std::vector<float> smoothedOpenness(const vao::VolumeView& view, const vao::Region& region,
  vao::Method method, vao::Radius r, double sigma, const std::vector<double>& thresholds = {})
{
  std::vector<float> out(region.voxelCount(), -1.0f);
  vao::AmbientOcclusionParameters p;
  p.method = method;
  p.radius = r;
  p.queryMode = vao::QueryMode::SmoothedValue;
  p.querySmoothing = sigma;
  p.thresholds = thresholds;
  const vao::Status status = vao::computeAmbientOcclusion(view, region, p, { out.data(), nullptr });
  EXPECT_TRUE(status.ok) << status.message;
  return out;
}

/// Every method with the smoothed query against its reference at the reference query.
/// A query within 1e-9 (relative, at most 1e-6) of a value of the box is that value for integer
/// data (the library snaps it, so that rounding cannot flip a count); for float data such voxels
/// are ambiguous and left out, and must be rare.
template <class T>
void expectSmoothedQuery(
  const std::vector<T>& v, const vao::Index3& dims, vao::Radius r, double sigma)
{
  SCOPED_TRACE(sigma);
  const auto view = viewOf(v, dims);
  const auto whole = vao::Region::whole(view);
  std::vector<double> t;
  ASSERT_TRUE(vao::volumeThresholds(view, 16, t).ok);
  const auto exactBox = smoothedOpenness(view, whole, vao::Method::ExactBox, r, sigma);
  const auto exactSphere = smoothedOpenness(view, whole, vao::Method::ExactSphere, r, sigma);
  const auto gauss = smoothedOpenness(view, whole, vao::Method::GaussianCdf, r, sigma);
  const auto histogram = smoothedOpenness(view, whole, vao::Method::HistogramCdf, r, sigma, t);
  std::int64_t k = 0, failures = 0, ambiguous = 0;
  for (std::int64_t z = 0; z < dims[2]; ++z)
    for (std::int64_t y = 0; y < dims[1]; ++y)
      for (std::int64_t x = 0; x < dims[0]; ++x, ++k)
      {
        double q = static_cast<double>(referenceQuery(v, dims, sigma, x, y, z));
        const double nearest = std::nearbyint(q);
        if (std::is_integral<T>::value &&
          std::abs(q - nearest) <= std::min(1e-9 * std::max(1.0, std::abs(nearest)), 1e-6))
          q = nearest;
        else if (!std::is_integral<T>::value)
        {
          bool close = false;
          for (const T value : v)
            close = close || std::abs(double(value) - q) <= 1e-9 * std::max(1.0, std::abs(q));
          if (close)
          {
            ++ambiguous;
            continue;
          }
        }
        const auto s = bruteForceStats(v, dims, r, x, y, z);
        const double expected[] = { bruteForceOpenness(v, dims, r, x, y, z, q, false),
          bruteForceOpenness(v, dims, r, x, y, z, q, true),
          reference::gaussianCdf(q, { s.mean, s.variance, s.minimum, s.maximum }, false),
          reference::histogramCdf(
            q, t, [&](double th) { return bruteForceOpenness(v, dims, r, x, y, z, th, false); }) };
        const float got[] = { exactBox[k], exactSphere[k], gauss[k], histogram[k] };
        for (int m = 0; m < 4; ++m)
          if (!(std::abs(got[m] - expected[m]) <= 2e-6) && failures++ < 8)
            ADD_FAILURE() << "method " << m << " at (" << x << "," << y << "," << z << ") q " << q
                          << ": " << got[m] << " vs " << expected[m];
      }
  EXPECT_EQ(failures, 0);
  EXPECT_LE(ambiguous, k / 100);
}

} // namespace

TEST(SmoothedQuery, EveryMethodUsesTheDefinitionsQuery)
{
  const vao::Index3 dims = { 15, 11, 9 };
  const auto v8 = randomVolume<std::uint8_t>(dims, 0, 6, 81); // ties: q often lands on a value
  const auto v16 = randomVolume<std::int16_t>(dims, -1024, 1600, 82);
  const auto vf = randomVolume<float>(dims, -1, 1, 83);
  for (double sigma : { 0.7, 1.0, 2.5 })
  {
    expectSmoothedQuery(v8, dims, { 2, 2, 2 }, sigma);
    expectSmoothedQuery(v16, dims, { 3, 1, 2 }, sigma);
    expectSmoothedQuery(vf, dims, { 1, 2, 3 }, sigma);
  }
  // CT values stored with an offset of 1e9: the queries keep their fractions.
  const auto v64 = randomVolume<std::int64_t>(dims, 1e9 - 1024, 1e9 + 1600, 85);
  expectSmoothedQuery(v64, dims, { 2, 1, 2 }, 1.0);
  // A long thin volume: the window is clipped on one axis only.
  const vao::Index3 thin = { 40, 3, 5 };
  expectSmoothedQuery(randomVolume<std::int16_t>(thin, 0, 4000, 84), thin, { 4, 1, 2 }, 1.3);
}

TEST(SmoothedQuery, AFlatRegionQueriesItsOwnValue)
{
  // A constant volume with one bump: far from the bump q = v exactly, so Exact Box is 1.
  const vao::Index3 dims = { 20, 20, 20 };
  std::vector<std::int16_t> v(8000, 1000);
  v[(10 * 20 + 10) * 20 + 10] = 1500;
  const auto view = viewOf(v, dims);
  const auto box =
    smoothedOpenness(view, vao::Region::whole(view), vao::Method::ExactBox, { 3, 3, 3 }, 1.0);
  EXPECT_EQ(box[0], 1.0f);
  EXPECT_EQ(box[(2 * 20 + 3) * 20 + 17], 1.0f);
  std::vector<double> fv(8000, 0.1);
  const auto fview = viewOf(fv, dims);
  const auto fbox =
    smoothedOpenness(fview, vao::Region::whole(fview), vao::Method::ExactBox, { 2, 2, 2 }, 2.5);
  for (const float o : fbox)
    ASSERT_EQ(o, 1.0f);
}

TEST(SmoothedQuery, APieceGrownByItsReachGivesTheWholeVolumesNumbers)
{
  const vao::Index3 dims = { 30, 24, 26 };
  const auto v = randomVolume<float>(dims, 0, 100, 91);
  const auto view = viewOf(v, dims);
  const double sigma = 1.7; // window 6 voxels: more than the radius
  ASSERT_EQ(vao::querySmoothingHalfWidth(sigma), 6);
  const vao::Radius r{ 2, 2, 2 };
  const auto whole =
    smoothedOpenness(view, vao::Region::whole(view), vao::Method::GaussianCdf, r, sigma);
  // The region x, y, z in [10, 20), grown by 6 (the larger reach) as its own block.
  std::vector<float> piece;
  for (std::int64_t z = 4; z < 26; ++z)
    for (std::int64_t y = 4; y < 24; ++y)
      for (std::int64_t x = 4; x < 26; ++x)
        piece.push_back(v[(z * dims[1] + y) * dims[0] + x]);
  const vao::Index3 pd = { 22, 20, 22 };
  const auto got = smoothedOpenness(
    viewOf(piece, pd), { { 6, 6, 6 }, { 10, 10, 10 } }, vao::Method::GaussianCdf, r, sigma);
  std::int64_t k = 0;
  for (std::int64_t z = 10; z < 20; ++z)
    for (std::int64_t y = 10; y < 20; ++y)
      for (std::int64_t x = 10; x < 20; ++x, ++k)
        ASSERT_EQ(got[k], whole[(z * dims[1] + y) * dims[0] + x]) << x << "," << y << "," << z;
}

TEST(SmoothedQuery, RefusesABadSigma)
{
  const vao::Index3 dims = { 8, 8, 8 };
  const auto v = randomVolume<std::int16_t>(dims, 0, 100, 95);
  const auto view = viewOf(v, dims);
  std::vector<float> out(view.voxelCount());
  vao::AmbientOcclusionParameters p;
  p.method = vao::Method::ExactBox;
  p.radius = { 2, 2, 2 };
  p.queryMode = vao::QueryMode::SmoothedValue;
  for (double sigma :
    { 0.0, -1.0, std::nan(""), std::numeric_limits<double>::infinity(), 100.5, 1e300 })
  {
    p.querySmoothing = sigma;
    const vao::Status status =
      vao::computeAmbientOcclusion(view, vao::Region::whole(view), p, { out.data(), nullptr });
    EXPECT_FALSE(status.ok) << sigma;
    EXPECT_NE(status.message.find("QuerySmoothing"), std::string::npos) << status.message;
  }
}

TEST(SmoothedQuery, RefusesValuesWhoseDifferencesOverflow)
{
  // Differences of +-1e305 overflow double: a clear failure, not NaN openness.
  const vao::Index3 dims = { 6, 6, 6 };
  std::vector<double> v(216, 1.0);
  v[10] = 1e305;
  v[20] = -1e305;
  const auto view = viewOf(v, dims);
  std::vector<float> out(216);
  vao::AmbientOcclusionParameters p;
  p.method = vao::Method::ExactBox;
  p.radius = { 1, 1, 1 };
  p.queryMode = vao::QueryMode::SmoothedValue;
  const vao::Status status =
    vao::computeAmbientOcclusion(view, vao::Region::whole(view), p, { out.data(), nullptr });
  EXPECT_FALSE(status.ok);
  EXPECT_NE(status.message.find("rescale"), std::string::npos) << status.message;
  // Without the smoothed query the exact count handles them.
  p.queryMode = vao::QueryMode::VoxelValue;
  EXPECT_TRUE(
    vao::computeAmbientOcclusion(view, vao::Region::whole(view), p, { out.data(), nullptr }).ok);
}
