#include "vtkVarianceOcclusionMap.h"

#include "vtkAmbientOcclusionInput.h"

#include "vao/VarianceOcclusionMap.h"

#include "vtkExtentTranslator.h"
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

namespace
{

/// Fine voxels of the input grid between a level voxel and the farthest input voxel it
/// depends on: level 0 blurs the input (2 taps each side), level l >= 1 blurs level l - 1,
/// whose spacing is 2^(l - 1) input voxels (2^l with half resolution), 2 taps each side.
int PyramidMargin(int levels, bool half)
{
  int margin = 2;
  for (int l = 1; l < levels; ++l)
  {
    margin += 2 << (l - 1 + (half ? 1 : 0));
  }
  return margin;
}

/// Input voxels between two voxels of the coarsest level: a piece's input must start on a
/// multiple of it, so that its levels keep the same voxels as the whole volume's.
int PyramidAlignment(int levels, bool half)
{
  return 1 << (levels - 1 + (half ? 1 : 0));
}

/// The piece of the whole extent this process outputs (ParaView's block decomposition).
void PieceExtent(vtkInformation* outInfo, const int whole[6], int piece[6])
{
  int index = 0, count = 1;
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER()))
  {
    index = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER());
    count = std::max(1, outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES()));
  }
  vtkNew<vtkExtentTranslator> translator;
  if (!translator->PieceToExtentThreadSafe(
        index, count, 0, const_cast<int*>(whole), piece, vtkExtentTranslator::BLOCK_MODE, 0))
  {
    piece[0] = piece[2] = piece[4] = 0; // more pieces than voxels: an empty piece
    piece[1] = piece[3] = piece[5] = -1;
  }
}

} // namespace

//------------------------------------------------------------------------------
void vtkVarianceOcclusionMap::InputExtentOf(const int whole[6], const int piece[6], int ext[6]) const
{
  const bool half = this->StartAtHalfResolution != 0;
  const int levels = std::max(1, std::min(this->NumberOfLevels, 16));
  const int margin = PyramidMargin(levels, half), align = PyramidAlignment(levels, half);
  for (int a = 0; a < 3; ++a)
  {
    const int lo = std::max(whole[2 * a], piece[2 * a] - margin);
    ext[2 * a] = whole[2 * a] + (lo - whole[2 * a]) / align * align;
    ext[2 * a + 1] = std::min(whole[2 * a + 1], piece[2 * a + 1] + margin);
  }
}

//------------------------------------------------------------------------------
int vtkVarianceOcclusionMap::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // Each level voxel depends on the input within PyramidMargin of it: a piece needs its
  // extent grown by that (aligned on the coarsest level's voxels), not the whole volume.
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  int whole[6], piece[6], ext[6];
  inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  PieceExtent(outputVector->GetInformationObject(0), whole, piece);
  if (piece[0] > piece[1] || piece[2] > piece[3] || piece[4] > piece[5])
  {
    std::copy(piece, piece + 6, ext); // nothing to output: ask for nothing
  }
  else
  {
    this->InputExtentOf(whole, piece, ext);
  }
  vtkAmbientOcclusionInput::RequestExactExtent(inInfo, ext);
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
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  int whole[6], piece[6], expected[6];
  inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  PieceExtent(outInfo, whole, piece);
  const int levels = std::max(0, this->NumberOfLevels);
  if (piece[0] > piece[1] || piece[2] > piece[3] || piece[4] > piece[5])
  {
    output->SetNumberOfBlocks(static_cast<unsigned int>(levels)); // an empty piece
    return 1;
  }
  this->InputExtentOf(whole, piece, expected);
  if (input && !std::equal(expected, expected + 6, input->GetExtent()))
  {
    vtkErrorMacro(<< "The variance occlusion map of this piece needs the input extent " << expected[0] << ".."
                  << expected[1] << ", " << expected[2] << ".." << expected[3] << ", " << expected[4] << ".."
                  << expected[5] << "; the upstream source delivered another one.");
    return 1;
  }
  std::string error;
  std::vector<vao::MomentLevel> pyramid;
  vtkAmbientOcclusionInput::ScalarVolume scalars;
  if (!input || !vtkAmbientOcclusionInput::CheckWholeExtent(whole, error) ||
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
  // Level l keeps every step-th input voxel (from the input's first, aligned on it); the
  // piece's level voxels are those whose input voxel lies in the piece.
  output->SetNumberOfBlocks(static_cast<unsigned int>(pyramid.size()));
  int step = this->StartAtHalfResolution ? 2 : 1;
  for (size_t l = 0; l < pyramid.size(); ++l, step *= 2)
  {
    vtkSmartPointer<vtkImageData> level = vtkAmbientOcclusionInput::LevelAsImage(pyramid[l]);
    int levelExt[6], wanted[6];
    double origin[3];
    for (int a = 0; a < 3; ++a)
    {
      const int first = (expected[2 * a] - whole[2 * a]) / step; // in the whole level's grid
      levelExt[2 * a] = first;
      levelExt[2 * a + 1] = first + level->GetDimensions()[a] - 1;
      origin[a] = level->GetOrigin()[a] - first * level->GetSpacing()[a];
      wanted[2 * a] = (piece[2 * a] - whole[2 * a] + step - 1) / step;
      wanted[2 * a + 1] = std::min(levelExt[2 * a + 1], (piece[2 * a + 1] - whole[2 * a]) / step);
    }
    level->SetExtent(levelExt);
    level->SetOrigin(origin);
    vtkNew<vtkImageData> part;
    if (wanted[0] <= wanted[1] && wanted[2] <= wanted[3] && wanted[4] <= wanted[5])
    {
      vtkAmbientOcclusionInput::CopyRequestedExtent(level, part, wanted);
    }
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
  os << indent << "Component: " << this->Component << "\n";
}
