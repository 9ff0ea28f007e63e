// vtkVolumetricAmbientOcclusion: what it refuses before computing, and why: parameters
// out of range, an input that does not cover the request, a radius that would make every
// neighbourhood the voxel alone or the whole volume.
#include "vtkVolumetricAmbientOcclusion.h"

#include "vtkAmbientOcclusionArrayInput.h"
#include "vtkAmbientOcclusionOpacity.h"

#include "vao/AmbientOcclusion.h"
#include "vao/HistogramCdf.h"
#include "vao/Validation.h"

#include "vtkImageData.h"
#include "vtkPiecewiseFunction.h"

#include <cmath>
#include <sstream>

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::CheckParameters()
{
  // The VTK side: enums, names, the radius before it becomes voxels. The kernel's own
  // checks (finiteness) keep its wording, with the property's name.
  std::ostringstream why;
  const std::string opacity = this->UsesOpacityFunction() && this->OpacityFunction
    ? vtkAmbientOcclusionOpacity::Check(this->OpacityFunction, "OpacityFunction")
    : std::string();
  const vao::Status iso = this->QueryMode == ISO_VALUE
    ? vao::checkFiniteParameter(this->IsoValue, "IsoValue")
    : vao::Status::success();
  if (!std::isfinite(this->Radius) || this->Radius < 0.0)
    why << "Radius must be a finite, non-negative number (got " << this->Radius << ").";
  else if (this->Method < CDF_RECONSTRUCTION || this->Method > RAYS)
    why << "Unknown Method " << this->Method
        << " (0 CDF Reconstruction, 1 Gaussian CDF, 2 Chebyshev, 3 Exact Box, 4 Exact Sphere, 5 "
           "Histogram CDF, 6 Transfer Function, 7 Exact Rays, 8 Rays).";
  else if (this->UsesOpacityFunction() && !this->OpacityFunction)
    why << "Method "
        << (this->Method == EXACT_RAYS ? "Exact Rays"
               : this->Method == RAYS  ? "Rays"
                                       : "Transfer Function")
        << " needs an opacity function (OpacityFunction): in ParaView "
           "the opacity transfer function of an array (GetOpacityTransferFunction), in VTK a "
           "vtkPiecewiseFunction.";
  else if (!opacity.empty())
    why << opacity;
  else if (this->Method == EXACT_RAYS &&
    (this->RayCount < 1 || this->RayCount > vao::kMaximumRayCount))
    why << "RayCount must lie in [1, " << vao::kMaximumRayCount << "] (got " << this->RayCount
        << ").";
  else if (this->CastsRays() &&
    !(std::isfinite(this->OpacityUnitDistance) && this->OpacityUnitDistance >= 0.0))
    why << "OpacityUnitDistance must be finite and positive, or 0 for the smallest spacing (got "
        << this->OpacityUnitDistance << ").";
  else if (this->Method == HISTOGRAM_CDF && !vao::checkHistogramBins(this->NumberOfBins).empty())
    why << vao::checkHistogramBins(this->NumberOfBins) << ".";
  else if (this->RadiusUnits != VOXELS && this->RadiusUnits != WORLD)
    why << "Unknown RadiusUnits " << this->RadiusUnits << " (0 Voxels, 1 World).";
  else if (this->QueryMode < VOXEL_VALUE || this->QueryMode > SMOOTHED_VALUE)
    why << "Unknown QueryMode " << this->QueryMode
        << " (0 Voxel Value, 1 Iso Value, 2 Smoothed Voxel Value).";
  else if (this->QueryMode == SMOOTHED_VALUE &&
    !vao::checkQuerySmoothing(this->QuerySmoothing).empty())
    why << vao::checkQuerySmoothing(this->QuerySmoothing) << ".";
  else if (!iso.ok)
    why << iso.message << ".";
  else if (this->ErfApproximation != ERF_EXACT && this->ErfApproximation != ERF_WINITZKI)
    why << "Unknown ErfApproximation " << this->ErfApproximation << " (0 Exact, 1 Winitzki).";
  else if (this->Backend < BACKEND_AUTO || this->Backend > BACKEND_CUDA)
    why << "Unknown Backend " << this->Backend << " (0 Auto, 1 CPU, 2 CUDA).";
  else if (this->Device < -1)
    why << "Device must be -1 (each MPI rank takes its node-local rank modulo the devices) or a "
           "device index, got "
        << this->Device << ".";
  else if (this->NumberOfThreads < 0)
    why << vtkAmbientOcclusionArrayInput::NumberOfThreadsError(this->NumberOfThreads);
  else if (this->OutputArrayName.empty())
    why << "OutputArrayName must not be empty.";
  else if (this->ComputeVariance && this->OutputArrayName == "Variance")
    why << "OutputArrayName 'Variance' is the name of the variance output (ComputeVariance), which "
           "would replace "
           "it: choose another name.";
  if (why.tellp() == 0)
  {
    return true;
  }
  vtkErrorMacro(<< why.str());
  return false;
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::CheckInputCovers(vtkImageData* input, const int outExt[6])
{
  const int* inExt = input->GetExtent();
  for (int a = 0; a < 3; ++a)
  {
    if (outExt[2 * a] < inExt[2 * a] || outExt[2 * a + 1] > inExt[2 * a + 1] ||
      outExt[2 * a] > outExt[2 * a + 1])
    {
      vtkErrorMacro(
        << "The input extent (" << inExt[0] << ".." << inExt[1] << ", " << inExt[2] << ".."
        << inExt[3] << ", " << inExt[4] << ".." << inExt[5]
        << ") does not cover the requested extent: the upstream source ignored the request.");
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::CheckVoxelRadius(
  vtkImageData* input, const int whole[6], int radius[3])
{
  const int wholeDims[3] = { whole[1] - whole[0] + 1, whole[3] - whole[2] + 1,
    whole[5] - whole[4] + 1 };
  const double* h = input->GetSpacing();
  if ((this->RadiusUnits == WORLD || this->CastsRays()) &&
    !(std::isfinite(h[0]) && h[0] > 0.0 && std::isfinite(h[1]) && h[1] > 0.0 &&
      std::isfinite(h[2]) && h[2] > 0.0))
  {
    vtkErrorMacro(<< (this->CastsRays() ? "Rays run in world space: they need"
                                        : "A radius in world units needs")
                  << " a finite, positive spacing on every axis; the input's is " << h[0] << ", "
                  << h[1] << ", " << h[2] << ". Fix the spacing (e.g. with Change Spacing)"
                  << (this->CastsRays() ? "." : " or give the radius in voxels."));
    return false;
  }
  this->ComputeVoxelRadius(h, radius);
  if (this->CastsRays())
  {
    // A ray may run beyond the volume (open sky there): any positive radius is a result.
    const vao::Status rays = vao::checkRayParameters(this->Rays(h));
    if (!rays.ok)
      vtkErrorMacro(<< (this->Method == RAYS ? "Rays: " : "Exact Rays: ") << rays.message << ".");
    return rays.ok;
  }
  if (radius[0] == 0 && radius[1] == 0 && radius[2] == 0)
  {
    vtkErrorMacro(
      << "Radius " << this->Radius << (this->RadiusUnits == WORLD ? " (world units)" : "")
      << " rounds to 0 voxels on every axis: the neighbourhood would be the voxel alone "
         "and the ambient occlusion 1 everywhere. Use at least one voxel.");
    return false;
  }
  if (radius[0] >= wholeDims[0] - 1 && radius[1] >= wholeDims[1] - 1 &&
    radius[2] >= wholeDims[2] - 1)
  {
    vtkErrorMacro(<< "Radius " << this->Radius << " (" << radius[0] << " x " << radius[1] << " x "
                  << radius[2] << " voxels) covers the whole " << wholeDims[0] << " x "
                  << wholeDims[1] << " x " << wholeDims[2]
                  << " volume from every voxel: every neighbourhood "
                  << "would be the whole volume. Use a smaller radius.");
    return false;
  }
  return true;
}
