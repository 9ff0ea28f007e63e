#include "vtkVarianceOcclusionMap.h"

#include "vtkAmbientOcclusionRequest.h"

#include "vtkAmbientOcclusionArrayInput.h"
#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionComposite.h"
#include "vtkAmbientOcclusionExtents.h"
#include "vtkAmbientOcclusionFrame.h"
#include "vtkAmbientOcclusionPyramidImages.h"

#include "vao/VarianceOcclusionMap.h"

#include "vtkCompositeDataSet.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiBlockDataSet.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <string>

vtkStandardNewMacro(vtkVarianceOcclusionMap);

namespace Extents = vtkAmbientOcclusionExtents;

//------------------------------------------------------------------------------
vtkVarianceOcclusionMap::vtkVarianceOcclusionMap()
{
  this->SetInputArrayToProcess(
    0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

//------------------------------------------------------------------------------
int vtkVarianceOcclusionMap::FillInputPortInformation(int, vtkInformation* info)
{
  vtkAmbientOcclusionComposite::AcceptImagesAndComposites(info);
  return 1;
}

//------------------------------------------------------------------------------
void vtkVarianceOcclusionMap::InputExtentOf(
  const int whole[6], const int piece[6], int ext[6]) const
{
  const bool half = this->StartAtHalfResolution != 0;
  const int levels = std::max(1, std::min(this->NumberOfLevels, 16));
  const int reach = Extents::PyramidReach(levels, half);
  const int reaches[3] = { reach, reach, reach };
  Extents::GrowForPyramid(whole, piece, reaches, Extents::PyramidAlignment(levels, half), ext);
}

//------------------------------------------------------------------------------
namespace
{
/// The processes that share a volume read by a reader that does not split (it reads on one
/// of them); nullptr in one process or from a source that splits.
vtkMultiProcessController* SharedController(vtkInformation* inputInformation)
{
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  return vtkAmbientOcclusionRequest::Distributed(controller) &&
      !Extents::CanProduceSubExtent(inputInformation)
    ? controller
    : nullptr;
}
}

//------------------------------------------------------------------------------
int vtkVarianceOcclusionMap::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // Each level voxel depends on the input within PyramidReach of it: a piece needs its
  // extent grown by that (aligned on the coarsest level's voxels), not the whole volume.
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  if (vtkAmbientOcclusionComposite::IsComposite(inInfo))
    return 1; // the piece request passes on as it is
  if (vtkMultiProcessController* controller = SharedController(inInfo))
  {
    // A reader that does not split: read on one process, fetched by ProduceOutput.
    Extents::RequestPieceOfWhole(
      inInfo, controller->GetLocalProcessId(), controller->GetNumberOfProcesses());
    return 1;
  }
  int whole[6], piece[6], ext[6];
  inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  Extents::RequestedPiece(outputVector->GetInformationObject(0), whole, piece);
  if (Extents::EmptyExtent(piece))
  {
    std::copy(piece, piece + 6, ext); // nothing to output: ask for nothing
  }
  else
  {
    this->InputExtentOf(whole, piece, ext);
  }
  Extents::RequestExactExtent(inInfo, ext);
  return 1;
}

//------------------------------------------------------------------------------
vao::PyramidParameters vtkVarianceOcclusionMap::Parameters() const
{
  vao::PyramidParameters parameters;
  parameters.levels = this->NumberOfLevels;
  parameters.startAtHalfResolution = this->StartAtHalfResolution != 0;
  return parameters;
}

//------------------------------------------------------------------------------
int vtkVarianceOcclusionMap::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (vtkAmbientOcclusionComposite::IsComposite(inputVector[0]->GetInformationObject(0)))
    return this->ProduceEachVolume(inputVector, outputVector);
  return vtkAmbientOcclusionRequest::ProduceOutput(this, outputVector,
    "try StartAtHalfResolution, fewer NumberOfLevels, or more MPI ranks.",
    [&] { return this->ProduceOutput(inputVector, outputVector); });
}

//------------------------------------------------------------------------------
int vtkVarianceOcclusionMap::ProduceEachVolume(
  vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // One volume: its levels, as from an image. Several: a block of levels per volume.
  vtkMultiBlockDataSet* output = vtkMultiBlockDataSet::GetData(outputVector);
  output->Initialize();
  std::string error;
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  const int rank = controller ? controller->GetLocalProcessId() : 0;
  const int ranks = controller ? controller->GetNumberOfProcesses() : 1;
  const bool done = vtkAmbientOcclusionComposite::ForEachVolume(
    controller, inputVector[0]->GetInformationObject(0),
    [&](int volume, int volumes, vtkInformation* inInfo)
    {
      vtkNew<vtkInformationVector> inputs, outputs;
      inputs->Append(inInfo);
      vtkNew<vtkInformation> outInfo;
      vtkNew<vtkMultiBlockDataSet> levels;
      outInfo->Set(vtkDataObject::DATA_OBJECT(), levels);
      outInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), rank);
      outInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), ranks);
      outputs->Append(outInfo);
      vtkInformationVector* in[1] = { inputs };
      this->RequestData(nullptr, in, outputs);
      if (levels->GetNumberOfBlocks() == 0 && this->NumberOfLevels > 0)
        return false; // it said why
      if (volumes == 1)
        output->ShallowCopy(levels);
      else
      {
        output->SetBlock(static_cast<unsigned int>(volume), levels);
        output->GetMetaData(static_cast<unsigned int>(volume))
          ->Set(vtkCompositeDataSet::NAME(), ("Volume " + std::to_string(volume)).c_str());
      }
      return true;
    },
    error);
  if (!done)
  {
    output->Initialize();
    if (!error.empty())
      vtkErrorMacro(<< error);
  }
  return 1;
}

//------------------------------------------------------------------------------
int vtkVarianceOcclusionMap::ProduceOutput(
  vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* input = vtkImageData::GetData(inputVector[0]);
  vtkMultiBlockDataSet* output = vtkMultiBlockDataSet::GetData(outputVector);
  output->Initialize();
  std::string error = vtkAmbientOcclusionRequest::ThreadsError(this->NumberOfThreads);
  if (!error.empty())
  {
    vtkErrorMacro(<< error);
    return 1;
  }
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  int whole[6], piece[6], expected[6];
  inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  Extents::RequestedPiece(outInfo, whole, piece);
  const int levels = std::max(0, this->NumberOfLevels);
  if (!Extents::EmptyExtent(piece))
  {
    this->InputExtentOf(whole, piece, expected);
  }
  vtkNew<vtkImageData> fetched;
  if (vtkMultiProcessController* controller = SharedController(inInfo))
  {
    // Collective: every process, also one with an empty piece, takes part.
    const int none[6] = { 0, -1, 0, -1, 0, -1 };
    input = vtkAmbientOcclusionCollectives::CoverNeededExtent(
      controller, input, whole, Extents::EmptyExtent(piece) ? none : expected, fetched, error);
    if (!input)
    {
      vtkErrorMacro(<< error);
      return 1;
    }
    if (!Extents::EmptyExtent(piece) && !std::equal(expected, expected + 6, input->GetExtent()))
    {
      vtkNew<vtkImageData> cropped;
      Extents::CopyRequestedExtent(input, cropped, expected);
      fetched->ShallowCopy(cropped);
      input = fetched;
    }
  }
  if (Extents::EmptyExtent(piece))
  {
    output->SetNumberOfBlocks(static_cast<unsigned int>(levels)); // an empty piece
    return 1;
  }
  if (input && !std::equal(expected, expected + 6, input->GetExtent()))
  {
    vtkErrorMacro(<< "The variance occlusion map of this piece needs the input extent "
                  << expected[0] << ".." << expected[1] << ", " << expected[2] << ".."
                  << expected[3] << ", " << expected[4] << ".." << expected[5]
                  << "; the upstream source delivered another one.");
    return 1;
  }
  std::vector<vao::MomentLevel> pyramid;
  vtkAmbientOcclusionArrayInput::ScalarVolume scalars;
  if (!input || !Extents::CheckWholeExtent(whole, error) ||
    !vtkAmbientOcclusionArrayInput::PrepareScalars(
      this, this->GetInputArrayToProcess(0, input), input, this->Component, scalars, error) ||
    !vtkAmbientOcclusionPyramidImages::BuildPyramid(scalars, input, this->Parameters(),
      vtkAmbientOcclusionRequest::Execution(this, this->NumberOfThreads), pyramid, error))
  {
    if (!error.empty())
    {
      vtkErrorMacro(<< error);
    }
    return 1;
  }
  vtkAmbientOcclusionPyramidImages::WarnOfCoarseMeans(this, pyramid);
  // Level l keeps every step-th input voxel (from the input's first, aligned on it); the
  // piece's level voxels are those whose input voxel lies in the piece.
  output->SetNumberOfBlocks(static_cast<unsigned int>(pyramid.size()));
  int step = this->StartAtHalfResolution ? 2 : 1;
  for (size_t l = 0; l < pyramid.size(); ++l, step *= 2)
  {
    auto part =
      vtkAmbientOcclusionPyramidImages::LevelPiece(pyramid[l], whole, expected, piece, step);
    vtkAmbientOcclusionFrame::PlaceInWorld(scalars.frame, part); // where the input's own voxels lie
    output->SetBlock(static_cast<unsigned int>(l), part);
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
  os << indent << "Component: " << this->Component << ", NumberOfThreads: " << this->NumberOfThreads
     << "\n";
}
