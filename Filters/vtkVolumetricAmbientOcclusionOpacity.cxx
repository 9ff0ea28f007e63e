// vtkVolumetricAmbientOcclusion: the opacity function of the Transfer Function method, kept
// as the caller's object (ParaView's opacity transfer function itself, so that an edit in
// the Color Map Editor is seen); vtkAmbientOcclusionOpacity turns it into the kernel's nodes.
#include "vtkVolumetricAmbientOcclusion.h"

#include "vtkPiecewiseFunction.h"

#include <algorithm>

//------------------------------------------------------------------------------
void vtkVolumetricAmbientOcclusion::SetOpacityFunction(vtkPiecewiseFunction* opacity)
{
  if (this->OpacityFunction != opacity)
  {
    this->OpacityFunction = opacity;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
vtkPiecewiseFunction* vtkVolumetricAmbientOcclusion::GetOpacityFunction() const
{
  return this->OpacityFunction;
}

//------------------------------------------------------------------------------
vtkMTimeType vtkVolumetricAmbientOcclusion::GetMTime()
{
  // An edited function (a point moved, a midpoint changed) re-executes the filter; the
  // other methods do not read it.
  const vtkMTimeType own = this->Superclass::GetMTime();
  return this->UsesOpacityFunction() && this->OpacityFunction
    ? std::max(own, this->OpacityFunction->GetMTime())
    : own;
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::UsesOpacityFunction() const
{
  return this->Method == TRANSFER_FUNCTION || this->CastsRays();
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::CastsRays() const
{
  return this->Method == EXACT_RAYS || this->Method == RAYS;
}
