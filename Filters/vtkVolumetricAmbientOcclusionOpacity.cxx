// vtkVolumetricAmbientOcclusion: the opacity function of the Transfer Function method, kept
// as the caller's object (ParaView's opacity transfer function itself, so that an edit in
// the Color Map Editor is seen) and handed to the kernel as its nodes.
#include "vtkVolumetricAmbientOcclusion.h"

#include "vao/TransferFunction.h"

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
  return this->Method == TRANSFER_FUNCTION && this->OpacityFunction
    ? std::max(own, this->OpacityFunction->GetMTime())
    : own;
}

//------------------------------------------------------------------------------
vao::OpacityFunction vtkVolumetricAmbientOcclusion::OpacityNodes() const
{
  vao::OpacityFunction nodes;
  if (!this->OpacityFunction)
  {
    return nodes;
  }
  vtkPiecewiseFunction* f = this->OpacityFunction;
  nodes.clamping = f->GetClamping() != 0;
  nodes.logScale = f->GetUseLogScale();
  for (int i = 0; i < f->GetSize(); ++i)
  {
    double node[4]; // x, opacity, midpoint, sharpness
    f->GetNodeValue(i, node);
    nodes.nodes.push_back({ node[0], node[1], node[2], node[3] });
  }
  return nodes;
}
