// The sums of the moment pyramid's 5-tap blur (PyramidBuild.cxx), written once for the
// CPU's rows (PyramidRows.h, inlined into their AVX2 and baseline forms) and the device's
// passes (cuda/PyramidPipeline.h). The order of the taps fixes the rounding, so both
// follow it term by term.
#pragma once

#if defined(__CUDACC__)
#define VAO_BLUR_INLINE __host__ __device__ __forceinline__
#elif defined(__GNUC__) || defined(__clang__)
#define VAO_BLUR_INLINE inline __attribute__((always_inline))
#else
#define VAO_BLUR_INLINE inline
#endif

namespace vao
{
namespace blur
{

constexpr int kTaps = 5;
constexpr int kHalf = 2;

/// sum_k w[k] v[k] in tap order.
VAO_BLUR_INLINE double tapSum(const double* w, const double* v)
{
  double sum = w[0] * v[0];
  for (int k = 1; k < kTaps; ++k)
    sum += w[k] * v[k];
  return sum;
}

/// sum_k w[k] d[k]^2 in tap order, each term (w d) d: the raw volume's second moment.
VAO_BLUR_INLINE double squareSum(const double* w, const double* d)
{
  double sum = w[0] * d[0] * d[0];
  for (int k = 1; k < kTaps; ++k)
    sum += w[k] * d[k] * d[k];
  return sum;
}

/// A level's stored mean and variance from the blurred moments a = E[d], b = E[d^2] about
/// the shift: mean = a + shift, variance = max(0, b - a^2), as float. The clamp follows
/// the conversion (the same float for every double): a conversion inside a condition can
/// raise a floating-point exception only on one side, so GCC would keep the branch and
/// the row loops would not vectorise.
VAO_BLUR_INLINE void levelMoments(double a, double b, double shift, float& mean, float& variance)
{
  mean = static_cast<float>(a + shift);
  const float var = static_cast<float>(b - a * a);
  variance = var > 0.0f ? var : 0.0f;
}

} // namespace blur
} // namespace vao
