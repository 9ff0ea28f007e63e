#include "vtkAmbientOcclusionInput.h"

#include "vtkAlgorithm.h"
#include "vtkCommunicator.h"
#include "vtkDataArray.h"
#include "vtkExtentTranslator.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <sstream>
#include <vector>

namespace vtkAmbientOcclusionInput
{
namespace
{

bool ToKernelType(int vtkType, vao::ScalarType& type)
{
  const bool longIs64 = sizeof(long) == 8;
  switch (vtkType)
  {
    case VTK_CHAR:
    case VTK_SIGNED_CHAR:
      type = vao::ScalarType::Int8;
      return true;
    case VTK_UNSIGNED_CHAR:
      type = vao::ScalarType::UInt8;
      return true;
    case VTK_SHORT:
      type = vao::ScalarType::Int16;
      return true;
    case VTK_UNSIGNED_SHORT:
      type = vao::ScalarType::UInt16;
      return true;
    case VTK_INT:
      type = vao::ScalarType::Int32;
      return true;
    case VTK_UNSIGNED_INT:
      type = vao::ScalarType::UInt32;
      return true;
    case VTK_LONG:
      type = longIs64 ? vao::ScalarType::Int64 : vao::ScalarType::Int32;
      return true;
    case VTK_LONG_LONG:
    case VTK_ID_TYPE:
      type = vao::ScalarType::Int64;
      return true;
    case VTK_UNSIGNED_LONG:
      type = longIs64 ? vao::ScalarType::UInt64 : vao::ScalarType::UInt32;
      return true;
    case VTK_UNSIGNED_LONG_LONG:
      type = vao::ScalarType::UInt64;
      return true;
    case VTK_FLOAT:
      type = vao::ScalarType::Float32;
      return true;
    case VTK_DOUBLE:
      type = vao::ScalarType::Float64;
      return true;
    default:
      return false;
  }
}

vtkDataArray* ChosenArray(vtkAlgorithm* algorithm, vtkDataArray* scalars, vtkImageData* input)
{
  const char* name = algorithm->GetInputArrayInformation(0)->Get(vtkDataObject::FIELD_NAME());
  if (!scalars && (!name || !*name))
  {
    // No array chosen (pvpython before the input was updated): the active point scalars.
    scalars = input->GetPointData()->GetScalars();
  }
  return scalars;
}

} // namespace

bool CheckWholeExtent(const int whole[6], std::string& error)
{
  const int dims[3] = { whole[1] - whole[0] + 1, whole[3] - whole[2] + 1, whole[5] - whole[4] + 1 };
  if (dims[0] >= 2 && dims[1] >= 2 && dims[2] >= 2)
  {
    return true;
  }
  std::ostringstream why;
  why << "The filter needs a 3-D volume; the input is " << std::max(dims[0], 0) << " x "
      << std::max(dims[1], 0) << " x " << std::max(dims[2], 0) << " voxels (empty, a single voxel, or 2-D).";
  error = why.str();
  return false;
}

bool PrepareScalars(vtkAlgorithm* algorithm, vtkDataArray* chosen, vtkImageData* input, int component,
  ScalarVolume& volume, std::string& error)
{
  std::ostringstream why;
  vtkDataArray* scalars = ChosenArray(algorithm, chosen, input);
  if (!scalars)
  {
    error = "No numeric point array to process: choose a point-data array of the image "
            "(the Scalars property; string and cell arrays are not accepted).";
    return false;
  }
  volume.name = scalars->GetName() ? scalars->GetName() : "";
  if (input->GetPointData()->GetAbstractArray(scalars->GetName()) != scalars)
  {
    error = "Array '" + volume.name + "' is not a point-data array; the filter works on points (voxels).";
    return false;
  }
  const int components = scalars->GetNumberOfComponents();
  const int picked = component < 0 && components == 1 ? 0 : component;
  if (picked < 0 || picked >= components)
  {
    why << "Array '" << volume.name << "' has " << components << " components; set Component to one of 0.."
        << components - 1 << " (got " << component << ").";
    error = why.str();
    return false;
  }
  vao::VolumeView& view = volume.view;
  if (!ToKernelType(scalars->GetDataType(), view.type))
  {
    error = "Array '" + volume.name + "' has unsupported type " + scalars->GetDataTypeAsString() + ".";
    return false;
  }
  const int* dims = input->GetDimensions();
  view.dims = { dims[0], dims[1], dims[2] };
  if (scalars->HasStandardMemoryLayout())
  {
    view.data = scalars->GetVoidPointer(picked);
    view.voxelStride = components;
  }
  else
  {
    volume.unpacked.resize(static_cast<size_t>(scalars->GetNumberOfTuples()));
    for (vtkIdType i = 0; i < scalars->GetNumberOfTuples(); ++i)
    {
      volume.unpacked[i] = scalars->GetComponent(i, picked);
    }
    view.data = volume.unpacked.data();
    view.type = vao::ScalarType::Float64;
    view.voxelStride = 1;
  }
  std::int64_t first = 0;
  const std::int64_t nonFinite = vao::countNonFinite(view, &first);
  if (nonFinite > 0)
  {
    const int* e = input->GetExtent();
    const std::int64_t plane = static_cast<std::int64_t>(dims[0]) * dims[1];
    why << "Array '" << volume.name << "' has " << nonFinite << " NaN or infinite values (the first at voxel "
        << first % dims[0] + e[0] << ", " << (first / dims[0]) % dims[1] + e[2] << ", " << first / plane + e[4]
        << "). A non-finite value has no place in a cumulative distribution or an isosurface: replace "
           "them (e.g. with the Calculator or Threshold filters) first.";
    error = why.str();
    return false;
  }
  return true;
}

bool EmptyExtent(const int ext[6])
{
  return ext[0] > ext[1] || ext[2] > ext[3] || ext[4] > ext[5];
}

vtkIdType ExtentPoints(const int ext[6])
{
  return EmptyExtent(ext) ? 0
                          : static_cast<vtkIdType>(ext[1] - ext[0] + 1) * (ext[3] - ext[2] + 1) *
      (ext[5] - ext[4] + 1);
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
  output->GetPointData()->CopyAllocate(input->GetPointData(), points);
  output->GetPointData()->CopyStructuredData(input->GetPointData(), inExt, outExt);
  output->GetFieldData()->ShallowCopy(input->GetFieldData());
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

void PieceOfWhole(int piece, int pieces, const int whole[6], int ext[6])
{
  vtkNew<vtkExtentTranslator> translator;
  if (!translator->PieceToExtentThreadSafe(
        piece, std::max(pieces, 1), 0, const_cast<int*>(whole), ext, vtkExtentTranslator::BLOCK_MODE, 0))
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

void GrowForPyramid(const int whole[6], const int piece[6], const int reach[3], int alignment, int ext[6])
{
  for (int a = 0; a < 3; ++a)
  {
    const int lo = std::max(whole[2 * a], piece[2 * a] - reach[a]);
    ext[2 * a] = whole[2 * a] + (lo - whole[2 * a]) / alignment * alignment;
    ext[2 * a + 1] = std::min(whole[2 * a + 1], piece[2 * a + 1] + reach[a]);
  }
}

void RequestExactExtent(vtkInformation* info, const int extent[6])
{
  info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), extent, 6);
  info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), 0);
  info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), 1);
  info->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
  info->Set(vtkStreamingDemandDrivenPipeline::EXACT_EXTENT(), 1);
}

void RequestWholeExtent(vtkInformation* info)
{
  int whole[6];
  info->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  RequestExactExtent(info, whole);
}

namespace
{

/// a and b overlap in `common` (false when they do not, or either is empty).
bool IntersectExtents(const int* a, const int* b, int common[6])
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

/// Copies the point arrays of `piece` (extent `pieceExt`, inside output's extent) into
/// output's arrays of the same names, row by row.
void PasteExtent(vtkImageData* piece, const int pieceExt[6], vtkImageData* output)
{
  const int* outExt = output->GetExtent();
  const vtkIdType pnx = pieceExt[1] - pieceExt[0] + 1, pny = pieceExt[3] - pieceExt[2] + 1;
  const vtkIdType onx = outExt[1] - outExt[0] + 1, ony = outExt[3] - outExt[2] + 1;
  vtkPointData* to = output->GetPointData();
  for (int a = 0; a < to->GetNumberOfArrays(); ++a)
  {
    vtkDataArray* target = to->GetArray(a);
    vtkDataArray* source = target ? piece->GetPointData()->GetArray(target->GetName()) : nullptr;
    if (!source || source->GetDataType() != target->GetDataType() ||
      source->GetNumberOfComponents() != target->GetNumberOfComponents())
    {
      continue;
    }
    const vtkIdType tupleBytes = target->GetNumberOfComponents() * target->GetDataTypeSize();
    const auto* from = static_cast<const char*>(source->GetVoidPointer(0));
    auto* into = static_cast<char*>(target->GetVoidPointer(0));
    for (int k = pieceExt[4]; k <= pieceExt[5]; ++k)
      for (int j = pieceExt[2]; j <= pieceExt[3]; ++j)
      {
        const vtkIdType src = ((k - pieceExt[4]) * pny + (j - pieceExt[2])) * pnx;
        const vtkIdType dst = ((k - outExt[4]) * ony + (j - outExt[2])) * onx + (pieceExt[0] - outExt[0]);
        std::copy(from + src * tupleBytes, from + (src + pnx) * tupleBytes, into + dst * tupleBytes);
      }
  }
}

} // namespace

double GlobalMax(vtkMultiProcessController* controller, double value)
{
  double result = value;
  controller->AllReduce(&value, &result, 1, vtkCommunicator::MAX_OP);
  return result;
}

void GlobalRange(vtkMultiProcessController* controller, double range[2])
{
  if (!controller || controller->GetNumberOfProcesses() < 2)
  {
    return;
  }
  const double local[2] = { range[0], range[1] };
  controller->AllReduce(&local[0], &range[0], 1, vtkCommunicator::MIN_OP);
  controller->AllReduce(&local[1], &range[1], 1, vtkCommunicator::MAX_OP);
}

void RedistributeExtents(vtkMultiProcessController* controller, vtkImageData* held,
  const int wanted[6], vtkImageData* output)
{
  const int ranks = controller->GetNumberOfProcesses(), rank = controller->GetLocalProcessId();
  std::vector<int> heldExtents(6 * ranks), wantedExtents(6 * ranks);
  controller->AllGather(held->GetExtent(), heldExtents.data(), 6);
  controller->AllGather(wanted, wantedExtents.data(), 6);

  output->Initialize();
  const bool wantsSomething = !EmptyExtent(wanted);
  if (wantsSomething)
  {
    const vtkIdType points = ExtentPoints(wanted);
    output->SetExtent(const_cast<int*>(wanted));
    output->SetOrigin(held->GetOrigin());
    output->SetSpacing(held->GetSpacing());
    output->SetDirectionMatrix(held->GetDirectionMatrix());
    vtkPointData* from = held->GetPointData();
    for (int a = 0; a < from->GetNumberOfArrays(); ++a)
    {
      vtkDataArray* array = from->GetArray(a);
      if (!array)
        continue;
      vtkSmartPointer<vtkDataArray> copy;
      copy.TakeReference(array->NewInstance());
      copy->SetName(array->GetName());
      copy->SetNumberOfComponents(array->GetNumberOfComponents());
      copy->SetNumberOfTuples(points);
      output->GetPointData()->AddArray(copy);
    }
    if (from->GetScalars())
      output->GetPointData()->SetActiveScalars(from->GetScalars()->GetName());
    output->GetFieldData()->ShallowCopy(held->GetFieldData());
    int common[6];
    if (IntersectExtents(held->GetExtent(), wanted, common))
    {
      vtkNew<vtkImageData> own;
      CopyRequestedExtent(held, own, common);
      PasteExtent(own, common, output);
    }
  }
  // Pairs in one global order, the lower rank sending first: no two wait on each other.
  constexpr int kPieceTag = 7102;
  for (int a = 0; a < ranks; ++a)
    for (int b = a + 1; b < ranks; ++b)
    {
      if (rank != a && rank != b)
        continue;
      const int other = rank == a ? b : a;
      auto send = [&] {
        int part[6];
        if (IntersectExtents(held->GetExtent(), &wantedExtents[6 * other], part))
        {
          vtkNew<vtkImageData> piece;
          CopyRequestedExtent(held, piece, part);
          controller->Send(piece.Get(), other, kPieceTag);
        }
      };
      auto receive = [&] {
        int part[6];
        if (wantsSomething && IntersectExtents(&heldExtents[6 * other], wanted, part))
        {
          vtkNew<vtkImageData> piece;
          controller->Receive(piece.Get(), other, kPieceTag);
          PasteExtent(piece, part, output); // the extent is known: the transport may not keep it
        }
      };
      if (rank == a)
      {
        send();
        receive();
      }
      else
      {
        receive();
        send();
      }
    }
}

vao::Execution ExecutionOf(vtkAlgorithm* algorithm)
{
  vao::Execution execution;
  execution.progress = [algorithm](double p) { algorithm->UpdateProgress(p); };
  execution.abortRequested = [algorithm] { return algorithm->GetAbortExecute() != 0; };
  return execution;
}

std::array<double, 3> ExtentOrigin(vtkImageData* image)
{
  const double* o = image->GetOrigin();
  const double* h = image->GetSpacing();
  const int* e = image->GetExtent();
  return { o[0] + e[0] * h[0], o[1] + e[2] * h[1], o[2] + e[4] * h[2] };
}

bool BuildPyramid(vtkAlgorithm* algorithm, const ScalarVolume& scalars, vtkImageData* input, int levels,
  bool startAtHalfResolution, std::vector<vao::MomentLevel>& pyramid, std::string& error)
{
  const double* h = input->GetSpacing();
  vao::PyramidParameters parameters;
  parameters.levels = levels;
  parameters.startAtHalfResolution = startAtHalfResolution;
  const vao::Status status = vao::buildMomentPyramid(
    scalars.view, ExtentOrigin(input), { h[0], h[1], h[2] }, parameters, pyramid, ExecutionOf(algorithm));
  if (!status.ok)
  {
    error = status.aborted ? "" : "The variance occlusion map failed: " + status.message + ".";
    return false;
  }
  return true;
}

vtkSmartPointer<vtkImageData> LevelAsImage(vao::MomentLevel& level)
{
  auto image = vtkSmartPointer<vtkImageData>::New();
  image->SetDimensions(static_cast<int>(level.dims[0]), static_cast<int>(level.dims[1]),
    static_cast<int>(level.dims[2]));
  image->SetOrigin(level.origin.data());
  image->SetSpacing(level.spacing.data());
  for (const auto& [name, values] : { std::make_pair("Mean", &level.mean), std::make_pair("Variance", &level.variance) })
  {
    // The level's block becomes the array's: no copy (a copy doubled the filter's peak).
    vtkNew<vtkFloatArray> array;
    array->SetName(name);
    const auto count = static_cast<vtkIdType>(values->size());
    array->SetArray(values->release(), count, 0, vtkAbstractArray::VTK_DATA_ARRAY_USER_DEFINED);
    array->SetArrayFreeFunction(&vao::detail::freeLevelStorage);
    image->GetPointData()->AddArray(array);
  }
  image->GetPointData()->SetActiveScalars("Mean");
  return image;
}


vtkSmartPointer<vtkImageData> LevelPiece(
  vao::MomentLevel& level, const int whole[6], const int inputExt[6], const int piece[6], int step)
{
  vtkSmartPointer<vtkImageData> image = LevelAsImage(level);
  int levelExt[6], wanted[6];
  double origin[3];
  for (int a = 0; a < 3; ++a)
  {
    const int first = (inputExt[2 * a] - whole[2 * a]) / step; // in the whole level's grid
    levelExt[2 * a] = first;
    levelExt[2 * a + 1] = first + image->GetDimensions()[a] - 1;
    origin[a] = image->GetOrigin()[a] - first * image->GetSpacing()[a];
    wanted[2 * a] = (piece[2 * a] - whole[2 * a] + step - 1) / step;
    wanted[2 * a + 1] = std::min(levelExt[2 * a + 1], (piece[2 * a + 1] - whole[2 * a]) / step);
  }
  image->SetExtent(levelExt);
  image->SetOrigin(origin);
  auto part = vtkSmartPointer<vtkImageData>::New();
  if (!EmptyExtent(wanted))
  {
    CopyRequestedExtent(image, part, wanted);
  }
  return part;
}

} // namespace vtkAmbientOcclusionInput
