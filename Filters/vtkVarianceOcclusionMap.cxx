#include "vtkVarianceOcclusionMap.h"

#include "vtkAmbientOcclusionInput.h"

#include "vao/VarianceOcclusionMap.h"

#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <string>

vtkStandardNewMacro(vtkVarianceOcclusionMap);

//------------------------------------------------------------------------------
vtkVarianceOcclusionMap::vtkVarianceOcclusionMap()
{
  this->SetInputArrayToProcess(
    0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

//------------------------------------------------------------------------------
int vtkVarianceOcclusionMap::FillInputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  return 1;
}

//------------------------------------------------------------------------------
int vtkVarianceOcclusionMap::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // The blur reaches across the whole volume level by level: ask for all of it.
  vtkAmbientOcclusionInput::RequestWholeExtent(inputVector[0]->GetInformationObject(0));
  return 1;
}

//------------------------------------------------------------------------------
int vtkVarianceOcclusionMap::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* input = vtkImageData::GetData(inputVector[0]);
  vtkMultiBlockDataSet* output = vtkMultiBlockDataSet::GetData(outputVector);
  output->Initialize();
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER()) &&
    outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER()) > 0)
  {
    // The pyramid is not distributed: piece 0 holds it whole, the other pieces the same
    // (empty) blocks, so a parallel run shows it once, as a serial one does.
    output->SetNumberOfBlocks(static_cast<unsigned int>(std::max(this->NumberOfLevels, 0)));
    return 1;
  }
  std::string error;
  std::vector<vao::MomentLevel> pyramid;
  vtkAmbientOcclusionInput::ScalarVolume scalars;
  if (!input || !vtkAmbientOcclusionInput::CheckWholeExtent(input->GetExtent(), error) ||
    !vtkAmbientOcclusionInput::PrepareScalars(
      this, this->GetInputArrayToProcess(0, inputVector), input, this->Component, scalars, error) ||
    !vtkAmbientOcclusionInput::BuildPyramid(
      this, scalars, input, this->NumberOfLevels, this->StartAtHalfResolution != 0, pyramid, error))
  {
    if (!error.empty())
    {
      vtkErrorMacro(<< error);
    }
    return 1;
  }
  output->SetNumberOfBlocks(static_cast<unsigned int>(pyramid.size()));
  for (size_t l = 0; l < pyramid.size(); ++l)
  {
    output->SetBlock(static_cast<unsigned int>(l), vtkAmbientOcclusionInput::LevelAsImage(pyramid[l]));
    output->GetMetaData(static_cast<unsigned int>(l))
      ->Set(vtkCompositeDataSet::NAME(), ("Level " + std::to_string(l)).c_str());
  }
  return 1;
}

//------------------------------------------------------------------------------
void vtkVarianceOcclusionMap::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "NumberOfLevels: " << this->NumberOfLevels << "\n";
  os << indent << "StartAtHalfResolution: " << this->StartAtHalfResolution << "\n";
  os << indent << "Component: " << this->Component << "\n";
}
