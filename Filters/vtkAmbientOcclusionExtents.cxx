#include "vtkAmbientOcclusionExtents.h"
#include "vtkAmbientOcclusionMemory.h"

#include "vtkAlgorithm.h"
#include "vtkExecutive.h"
#include "vtkInformationExecutivePortKey.h"

#include "vtkExtentTranslator.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace vtkAmbientOcclusionExtents
{

bool CheckWholeExtent(const int whole[6], std::string& error)
{
  const int dims[3] = { whole[1] - whole[0] + 1, whole[3] - whole[2] + 1, whole[5] - whole[4] + 1 };
  if (dims[0] >= 2 && dims[1] >= 2 && dims[2] >= 2)
  {
    return true;
  }
  std::ostringstream why;
  why << "The filter needs a 3-D volume; the input is " << std::max(dims[0], 0) << " x "
      << std::max(dims[1], 0) << " x " << std::max(dims[2], 0)
      << " voxels (empty, a single voxel, or 2-D).";
  error = why.str();
  return false;
}

bool WholeAndRequestedExtent(vtkInformationVector* inputs, vtkInformationVector* outputs,
  int whole[6], int requested[6], std::string& error)
{
  inputs->GetInformationObject(0)->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  outputs->GetInformationObject(0)->Get(
    vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), requested);
  return CheckWholeExtent(whole, error);
}

bool EmptyExtent(const int ext[6])
{
  return ext[0] > ext[1] || ext[2] > ext[3] || ext[4] > ext[5];
}

vtkIdType ExtentPoints(const int ext[6])
{
  return EmptyExtent(ext)
    ? 0
    : static_cast<vtkIdType>(ext[1] - ext[0] + 1) * (ext[3] - ext[2] + 1) * (ext[5] - ext[4] + 1);
}

bool IntersectExtents(const int a[6], const int b[6], int common[6])
{
  for (int axis = 0; axis < 3; ++axis)
  {
    common[2 * axis] = std::max(a[2 * axis], b[2 * axis]);
    common[2 * axis + 1] = std::min(a[2 * axis + 1], b[2 * axis + 1]);
    if (common[2 * axis] > common[2 * axis + 1])
    {
      return false;
    }
  }
  return true;
}

void GrowExtent(int ext[6], const int r[3], const int whole[6])
{
  for (int a = 0; a < 3; ++a)
  {
    ext[2 * a] = std::max(ext[2 * a] - r[a], whole[2 * a]);
    ext[2 * a + 1] = std::min(ext[2 * a + 1] + r[a], whole[2 * a + 1]);
  }
}

void CopyRequestedExtent(vtkImageData* input, vtkImageData* output, const int outExt[6])
{
  const int* inExt = input->GetExtent();
  if (std::equal(outExt, outExt + 6, inExt))
  {
    output->ShallowCopy(input);
    return;
  }
  const vtkIdType points = ExtentPoints(outExt);
  output->SetExtent(const_cast<int*>(outExt));
  output->SetOrigin(input->GetOrigin());
  output->SetSpacing(input->GetSpacing());
  output->SetDirectionMatrix(input->GetDirectionMatrix());
  double bytes = 0.0;
  for (int a = 0; a < input->GetPointData()->GetNumberOfArrays(); ++a)
  {
    if (vtkAbstractArray* array = input->GetPointData()->GetAbstractArray(a))
      bytes +=
        static_cast<double>(points) * array->GetNumberOfComponents() * array->GetDataTypeSize();
  }
  vtkAmbientOcclusionMemory::Reserve(bytes, "the input's arrays cropped to the requested extent");
  output->GetPointData()->CopyAllocate(input->GetPointData(), points);
  output->GetPointData()->CopyStructuredData(input->GetPointData(), inExt, outExt);
  output->GetFieldData()->ShallowCopy(input->GetFieldData());
}

void PieceOfWhole(int piece, int pieces, const int whole[6], int ext[6])
{
  vtkNew<vtkExtentTranslator> translator;
  if (!translator->PieceToExtentThreadSafe(piece, std::max(pieces, 1), 0, const_cast<int*>(whole),
        ext, vtkExtentTranslator::BLOCK_MODE, 0))
  {
    ext[0] = ext[2] = ext[4] = 0; // more pieces than voxels: an empty piece
    ext[1] = ext[3] = ext[5] = -1;
  }
}

void RequestedPiece(vtkInformation* outInfo, const int whole[6], int ext[6])
{
  int index = 0, count = 1;
  if (outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER()))
  {
    index = outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER());
    count = std::max(1, outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES()));
  }
  PieceOfWhole(index, count, whole, ext);
}

int PyramidReach(int levels, bool half)
{
  // Level 0 blurs the input (2 taps each side); level l >= 1 blurs level l - 1, whose
  // spacing is 2^(l - 1) input voxels (2^l from half resolution), 2 taps each side.
  int reach = 2;
  for (int l = 1; l < levels; ++l)
  {
    reach += 2 << (l - 1 + (half ? 1 : 0));
  }
  return reach;
}

int PyramidAlignment(int levels, bool half)
{
  return 1 << (std::max(levels, 1) - 1 + (half ? 1 : 0));
}

void GrowForPyramid(
  const int whole[6], const int piece[6], const int reach[3], int alignment, int ext[6])
{
  for (int a = 0; a < 3; ++a)
  {
    const int lo = std::max(whole[2 * a], piece[2 * a] - reach[a]);
    ext[2 * a] = whole[2 * a] + (lo - whole[2 * a]) / alignment * alignment;
    ext[2 * a + 1] = std::min(whole[2 * a + 1], piece[2 * a + 1] + reach[a]);
  }
}

void GrowForSurfaceQueries(const int whole[6], const int piece[6], const double spacing[3],
  int levels, bool half, double offsetFactor, int slack, int ext[6])
{
  // How far from a surface point the finer levels (0 .. L-2) are sampled: AO at
  // k * r_l along the normal, shadows from r_0 out to r_0 * 2^(l+1) (where level l + 1
  // takes over), the gradient and the half-voxel query within a voxel; plus the
  // trilinear reach of the level's grid. Every voxel of those levels there must be right:
  // plus their own reach in the input. The coarsest level must be right over the piece.
  const double largest = std::max({ spacing[0], spacing[1], spacing[2] });
  const double r0 = 2.0 * largest * (half ? 2 : 1);
  double reach = 2.0 * largest;
  for (int l = 0; l + 1 < levels; ++l)
  {
    const double step = static_cast<double>((half ? 2 : 1) << l);
    const double r = r0 * (1 << l);
    reach = std::max(reach, std::max(offsetFactor * r, r0 * (2 << l)) + step * largest);
  }
  int reaches[3];
  for (int a = 0; a < 3; ++a)
  {
    reaches[a] = std::max(PyramidReach(levels, half),
      static_cast<int>(std::ceil(reach / spacing[a])) + 1 + slack + PyramidReach(levels - 1, half));
  }
  GrowForPyramid(whole, piece, reaches, PyramidAlignment(levels, half), ext);
}

void RequestExactExtent(vtkInformation* info, const int extent[6])
{
  info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), extent, 6);
  info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), 0);
  info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), 1);
  info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
  info->Set(vtkStreamingDemandDrivenPipeline::EXACT_EXTENT(), 1);
}

bool CanProduceSubExtent(vtkInformation* info)
{
  for (int depth = 0; info && depth < 1000; ++depth)
  {
    if (info->Has(vtkAlgorithm::CAN_PRODUCE_SUB_EXTENT()) &&
      info->Get(vtkAlgorithm::CAN_PRODUCE_SUB_EXTENT()) != 0)
      return true;
    vtkExecutive* producer = nullptr;
    int port = 0;
    vtkExecutive::PRODUCER()->Get(info, producer, port);
    vtkAlgorithm* algorithm = producer ? producer->GetAlgorithm() : nullptr;
    if (!algorithm) // data without a pipeline behind it: nothing reads a file, unless the
      return !info->Has(vtkAlgorithm::CAN_PRODUCE_SUB_EXTENT()); // pieces were handed over
    if (algorithm->GetNumberOfInputPorts() == 0 || algorithm->GetNumberOfInputConnections(0) == 0)
      return false; // a source that did not say it can
    info = producer->GetInputInformation(0, 0);
  }
  return false;
}

void RequestPieceOfWhole(vtkInformation* info, int piece, int pieces)
{
  int whole[6];
  info->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), whole, 6);
  info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), piece);
  info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), pieces);
  info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
}

void RequestWholeExtent(vtkInformation* info)
{
  int whole[6];
  info->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  RequestExactExtent(info, whole);
}

} // namespace vtkAmbientOcclusionExtents
