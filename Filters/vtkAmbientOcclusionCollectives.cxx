#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionMemory.h"

#include "vtkAmbientOcclusionExtents.h"

#include "vao/VarianceOcclusionMap.h"

#include "vtkCommunicator.h"
#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <vector>

namespace vtkAmbientOcclusionCollectives
{
namespace
{

using vtkAmbientOcclusionExtents::CopyRequestedExtent;
using vtkAmbientOcclusionExtents::EmptyExtent;
using vtkAmbientOcclusionExtents::ExtentPoints;
using vtkAmbientOcclusionExtents::IntersectExtents;

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
        const vtkIdType dst =
          ((k - outExt[4]) * ony + (j - outExt[2])) * onx + (pieceExt[0] - outExt[0]);
        std::copy(
          from + src * tupleBytes, from + (src + pnx) * tupleBytes, into + dst * tupleBytes);
      }
  }
}

/// `output` as the `wanted` extent of held's grid, with arrays like held's (their values
/// not set) and held's field data; then the part of held that lies in it.
void AllocateWanted(vtkImageData* held, const int wanted[6], vtkImageData* output)
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
    vtkAmbientOcclusionMemory::Allocate(
      copy, points, std::string("the redistributed array ") + array->GetName());
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

/// Per process: where its floats start in an all-gathered buffer, and how many it sent.
struct GatheredLayout
{
  std::vector<vtkIdType> lengths, offsets;
  vtkIdType total = 0;
};

GatheredLayout LayoutOf(const std::vector<int>& extents, int valuesPerPoint)
{
  GatheredLayout layout;
  const size_t ranks = extents.size() / 6;
  for (size_t r = 0; r < ranks; ++r)
  {
    layout.lengths.push_back(valuesPerPoint * ExtentPoints(&extents[6 * r]));
    layout.offsets.push_back(layout.total);
    layout.total += layout.lengths.back();
  }
  return layout;
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
    AllocateWanted(held, wanted, output);
  }
  // Pairs in one global order, the lower rank sending first: no two wait on each other.
  constexpr int kPieceTag = 7102;
  for (int a = 0; a < ranks; ++a)
    for (int b = a + 1; b < ranks; ++b)
    {
      if (rank != a && rank != b)
        continue;
      const int other = rank == a ? b : a;
      auto send = [&]
      {
        int part[6];
        if (IntersectExtents(held->GetExtent(), &wantedExtents[6 * other], part))
        {
          vtkNew<vtkImageData> piece;
          CopyRequestedExtent(held, piece, part);
          controller->Send(piece.Get(), other, kPieceTag);
        }
      };
      auto receive = [&]
      {
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

void GatherLevel(vtkMultiProcessController* controller, vtkImageData* part, vao::MomentLevel& level)
{
  int ext[6] = { 0, -1, 0, -1, 0, -1 };
  std::vector<float> mine; // the piece's Mean, then its Variance
  if (part && part->GetNumberOfPoints() > 0)
  {
    part->GetExtent(ext);
    for (const char* name : { "Mean", "Variance" })
    {
      vtkDataArray* values = part->GetPointData()->GetArray(name);
      for (vtkIdType i = 0; i < values->GetNumberOfTuples(); ++i)
        mine.push_back(static_cast<float>(values->GetTuple1(i)));
    }
  }
  std::vector<int> extents(static_cast<size_t>(6 * controller->GetNumberOfProcesses()));
  controller->AllGather(ext, extents.data(), 6);
  GatheredLayout layout = LayoutOf(extents, 2);
  std::vector<float> all(static_cast<size_t>(std::max<vtkIdType>(layout.total, 1)));
  controller->AllGatherV(mine.data(), all.data(), static_cast<vtkIdType>(mine.size()),
    layout.lengths.data(), layout.offsets.data());

  const vtkIdType nx = level.dims[0], ny = level.dims[1];
  level.mean.resize(static_cast<size_t>(nx * ny * level.dims[2]));
  level.variance.resize(level.mean.size());
  for (size_t r = 0; r < layout.lengths.size(); ++r)
  {
    const int* e = &extents[6 * r];
    const float* from = all.data() + layout.offsets[r];
    const vtkIdType count = layout.lengths[r] / 2;
    vtkIdType i = 0;
    for (int k = e[4]; k <= e[5]; ++k)
      for (int j = e[2]; j <= e[3]; ++j)
        for (int x = e[0]; x <= e[1]; ++x, ++i)
        {
          const vtkIdType at = (static_cast<vtkIdType>(k) * ny + j) * nx + x;
          level.mean[at] = from[i];
          level.variance[at] = from[count + i];
        }
  }
}

} // namespace vtkAmbientOcclusionCollectives
