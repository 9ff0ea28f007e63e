// Shading with ambient occlusion, written once for host and device: Ruiz et al.'s
// ambient lighting (Eq. 5) and opacity modulation by the intensity variance (section 4.2).
#pragma once

#include "vao/Estimators.h"

namespace vao
{

/// Colour channel of Eq. 5: k * O * C_TF, clamped to [0, 1]; O raised to 1/gamma first.
VAO_HD double ambientLighting(double k, double openness, double channel, double gamma)
{
  const double o = gamma == 1.0 ? openness : pow(clamp01(openness), 1.0 / gamma);
  return clamp01(k * o * channel);
}

/// Opacity modulation factor m = min(s2 / s2max, 1) (section 4.2): homogeneous regions
/// (low variance) fade, boundaries stay.
VAO_HD double varianceModulation(double variance, double varianceMax)
{
  return varianceMax > 0.0 ? clamp01(variance / varianceMax) : 1.0;
}

/// A value in [0, 1] as an 8-bit channel; NaN gives 0 (casting NaN to an integer is
/// undefined behaviour).
VAO_HD unsigned char toByte(double unit)
{
  return unit > 0.0 ? static_cast<unsigned char>(clamp01(unit) * 255.0 + 0.5)
                    : static_cast<unsigned char>(0);
}

} // namespace vao
