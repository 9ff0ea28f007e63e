#include "vtkOcclusionSweeping.h"

#include "vtkAmbientOcclusionInput.h"

#include "vao/OcclusionSweeping.h"

#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <vector>

vtkStandardNewMacro(vtkOcclusionSweeping);

//------------------------------------------------------------------------------
vtkOcclusionSweeping::vtkOcclusionSweeping()
{
  this->SetInputArrayToProcess(
    0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

//------------------------------------------------------------------------------
int vtkOcclusionSweeping::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  // Any piece can be produced, from the whole volume (see RequestUpdateExtent).
  outputVector->GetInformationObject(0)->Set(CAN_PRODUCE_SUB_EXTENT(), 1);
  return 1;
}

//------------------------------------------------------------------------------
int vtkOcclusionSweeping::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // Sweeping is global: an occluder anywhere shadows everything behind it, so every
  // piece is computed from the whole volume.
  vtkAmbientOcclusionInput::RequestWholeExtent(inputVector[0]->GetInformationObject(0));
  return 1;
}

//------------------------------------------------------------------------------
int vtkOcclusionSweeping::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkImageData* input = vtkImageData::GetData(inInfo);
  vtkImageData* output = vtkImageData::GetData(outInfo);
  output->Initialize();
  if (!input)
  {
    return 1;
  }
  int whole[6], outExt[6];
  inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), outExt);
  std::string error;
  if (!vtkAmbientOcclusionInput::CheckWholeExtent(whole, error))
  {
    vtkErrorMacro(<< error);
    return 1;
  }
  const int* inExt = input->GetExtent();
  if (!std::equal(whole, whole + 6, inExt))
  {
    vtkErrorMacro(<< "Occlusion sweeping needs the whole volume; the upstream source delivered only part of it.");
    return 1;
  }
  vtkAmbientOcclusionInput::ScalarVolume scalars;
  if (!vtkAmbientOcclusionInput::PrepareScalars(
        this, this->GetInputArrayToProcess(0, inputVector), input, this->Component, scalars, error))
  {
    vtkErrorMacro(<< error);
    return 1;
  }

  vao::SweepParameters parameters;
  parameters.isoValue = this->IsoValue;
  parameters.insideIsAbove = this->InsideIsAbove != 0;
  parameters.iterations = this->NumberOfIterations;
  parameters.tolerance = this->ConvergenceTolerance;
  for (int s = 0; s < 8; ++s)
  {
    parameters.octantMask[s] = this->OctantMask[s] != 0;
  }
  parameters.useGeometryTerm = this->UseGeometryTerm != 0;
  parameters.gamma = this->Gamma;
  parameters.opacity = this->Opacity;

  const vtkIdType points = input->GetNumberOfPoints();
  auto newArray = [points](const char* name, int components) {
    vtkNew<vtkFloatArray> array;
    array->SetName(name);
    array->SetNumberOfComponents(components);
    array->SetNumberOfTuples(points);
    return array;
  };
  auto distance = newArray("SignedDistance", 1);
  auto occlusion = newArray("AmbientOcclusion", 1);
  vtkSmartPointer<vtkFloatArray> octants;
  if (this->OutputOctantVisibility)
  {
    octants = newArray("OctantVisibility", 8).Get();
  }
  const double* spacing = input->GetSpacing();
  const vao::Execution execution = vtkAmbientOcclusionInput::ExecutionOf(this);
  vao::SweepReport report;
  const vao::Status status = vao::computeOcclusionSweeping(scalars.view, { spacing[0], spacing[1], spacing[2] },
    parameters, { distance->GetPointer(0), occlusion->GetPointer(0), octants ? octants->GetPointer(0) : nullptr },
    execution, &report);
  if (!status.ok)
  {
    if (!status.aborted)
    {
      vtkErrorMacro(<< "Occlusion sweeping failed: " << status.message << ".");
    }
    return 1;
  }
  if (!report.surfaceFound)
  {
    vtkWarningMacro(<< "IsoValue " << this->IsoValue << " does not cross array '" << scalars.name
                    << "': there is no surface; every voxel is "
                    << "entirely inside or outside (AmbientOcclusion 0 or 1).");
  }
  this->LastPasses = report.passes;
  this->LastChange = report.lastChange;

  // Computed on the whole volume; the output is the requested extent.
  vtkNew<vtkImageData> whole3d;
  whole3d->ShallowCopy(input);
  whole3d->GetPointData()->AddArray(distance);
  whole3d->GetPointData()->AddArray(occlusion);
  if (octants)
  {
    whole3d->GetPointData()->AddArray(octants);
  }
  vtkAmbientOcclusionInput::CopyRequestedExtent(whole3d, output, outExt);
  return 1;
}

//------------------------------------------------------------------------------
void vtkOcclusionSweeping::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "IsoValue: " << this->IsoValue << " (inside is " << (this->InsideIsAbove ? "above" : "below")
     << ")\n";
  os << indent << "NumberOfIterations: " << this->NumberOfIterations << ", ConvergenceTolerance: "
     << this->ConvergenceTolerance << "\n";
  os << indent << "UseGeometryTerm: " << this->UseGeometryTerm << "\n";
  os << indent << "OctantMask:";
  for (int s = 0; s < 8; ++s)
  {
    os << " " << this->OctantMask[s];
  }
  os << "\n" << indent << "Gamma: " << this->Gamma << ", Opacity: " << this->Opacity << "\n";
  os << indent << "OutputOctantVisibility: " << this->OutputOctantVisibility << "\n";
  os << indent << "Component: " << this->Component << "\n";
}
