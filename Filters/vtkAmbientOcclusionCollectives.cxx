#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionMemory.h"

#include "vtkAmbientOcclusionExtents.h"

#include "vao/VarianceOcclusionMap.h"

#include "vtkCommunicator.h"
#include "vtkDataArray.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

namespace vtkAmbientOcclusionCollectives
{
namespace
{

using vtkAmbientOcclusionExtents::CopyRequestedExtent;
using vtkAmbientOcclusionExtents::EmptyExtent;
using vtkAmbientOcclusionExtents::ExtentPoints;
using vtkAmbientOcclusionExtents::IntersectExtents;

struct Box
{
  int ext[6];
};

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

/// `output` as the `wanted` extent of `like`'s grid (origin, spacing and direction from
/// `geometry`), with arrays like `like`'s (their values not set), its active scalars and
/// its field data.
void AllocateWanted(
  vtkImageData* like, const double geometry[15], const int wanted[6], vtkImageData* output)
{
  const vtkIdType points = ExtentPoints(wanted);
  output->SetExtent(const_cast<int*>(wanted));
  output->SetOrigin(geometry);
  output->SetSpacing(geometry + 3);
  output->SetDirectionMatrix(geometry + 6);
  vtkPointData* from = like->GetPointData();
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
  output->GetFieldData()->ShallowCopy(like->GetFieldData());
}

/// The parts of `box` outside `hole`, as at most six boxes appended to `parts`.
void Subtract(const Box& box, const int hole[6], std::vector<Box>& parts)
{
  int common[6];
  if (!IntersectExtents(box.ext, hole, common))
  {
    parts.push_back(box);
    return;
  }
  Box rest = box;
  for (int a = 0; a < 3; ++a)
  {
    if (rest.ext[2 * a] < common[2 * a])
    {
      Box below = rest;
      below.ext[2 * a + 1] = common[2 * a] - 1;
      parts.push_back(below);
      rest.ext[2 * a] = common[2 * a];
    }
    if (rest.ext[2 * a + 1] > common[2 * a + 1])
    {
      Box above = rest;
      above.ext[2 * a] = common[2 * a + 1] + 1;
      parts.push_back(above);
      rest.ext[2 * a + 1] = common[2 * a + 1];
    }
  }
}

} // namespace

std::vector<Transfer> PlanTransfers(
  const std::vector<int>& held, const std::vector<int>& wanted, bool& complete)
{
  const int ranks = static_cast<int>(held.size() / 6);
  std::vector<Transfer> plan;
  complete = true;
  for (int to = 0; to < ranks; ++to)
  {
    std::vector<Box> remaining;
    if (!EmptyExtent(&wanted[6 * to]))
      remaining.push_back(Box{ { wanted[6 * to], wanted[6 * to + 1], wanted[6 * to + 2],
        wanted[6 * to + 3], wanted[6 * to + 4], wanted[6 * to + 5] } });
    // Its own block first (no message), then the others' in rank order.
    for (int k = -1; k < ranks && !remaining.empty(); ++k)
    {
      const int from = k < 0 ? to : k;
      if ((k >= 0 && from == to) || EmptyExtent(&held[6 * from]))
        continue;
      std::vector<Box> next;
      for (const Box& box : remaining)
      {
        Transfer part{ from, to, {} };
        if (IntersectExtents(box.ext, &held[6 * from], part.ext))
          plan.push_back(part);
        Subtract(box, &held[6 * from], next);
      }
      remaining.swap(next);
    }
    complete = complete && remaining.empty();
  }
  return plan;
}

namespace
{

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

bool RedistributeExtents(vtkMultiProcessController* controller, vtkImageData* held,
  const int wanted[6], vtkImageData* output)
{
  const int ranks = controller->GetNumberOfProcesses(), rank = controller->GetLocalProcessId();
  int heldExtent[6] = { 0, -1, 0, -1, 0, -1 };
  if (held->GetNumberOfPoints() > 0)
    held->GetExtent(heldExtent);
  std::vector<int> heldExtents(6 * ranks), wantedExtents(6 * ranks);
  controller->AllGather(heldExtent, heldExtents.data(), 6);
  controller->AllGather(wanted, wantedExtents.data(), 6);
  // The grid from a process that holds voxels: a reader that does not split (MetaImage,
  // NRRD) hands the others an empty image without one.
  double geometry[15];
  held->GetOrigin(geometry);
  held->GetSpacing(geometry + 3);
  std::copy(
    held->GetDirectionMatrix()->GetData(), held->GetDirectionMatrix()->GetData() + 9, geometry + 6);
  std::vector<double> geometries(15 * ranks);
  controller->AllGather(geometry, geometries.data(), 15);
  for (int r = 0; r < ranks; ++r)
    if (!EmptyExtent(&heldExtents[6 * r]))
    {
      std::copy(&geometries[15 * r], &geometries[15 * r] + 15, geometry);
      break;
    }

  output->Initialize();
  bool complete = true;
  const std::vector<Transfer> plan = PlanTransfers(heldExtents, wantedExtents, complete);
  if (!complete)
    return false;
  const bool wantsSomething = !EmptyExtent(wanted);
  if (wantsSomething && !EmptyExtent(heldExtent))
    AllocateWanted(held, geometry, wanted, output);
  // Pairs in one global order, the lower rank sending first: no two wait on each other.
  constexpr int kPieceTag = 7102;
  for (int a = 0; a < ranks; ++a)
    for (int b = a; b < ranks; ++b)
    {
      if (rank != a && rank != b)
        continue;
      const int other = rank == a ? b : a;
      auto send = [&]
      {
        for (const Transfer& part : plan)
          if (part.from == rank && part.to == other && other != rank)
          {
            vtkNew<vtkImageData> piece;
            CopyRequestedExtent(held, piece, part.ext);
            controller->Send(piece.Get(), other, kPieceTag);
          }
      };
      auto receive = [&]
      {
        for (const Transfer& part : plan)
          if (part.to == rank && part.from == other)
          {
            vtkNew<vtkImageData> piece;
            if (other == rank)
              CopyRequestedExtent(held, piece, part.ext);
            else
              controller->Receive(piece.Get(), other, kPieceTag);
            if (output->GetNumberOfPoints() == 0)
              AllocateWanted(piece, geometry, wanted, output);
            PasteExtent(piece, part.ext, output); // the transport may not keep the extent
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
  return true;
}

vtkImageData* CoverNeededExtent(vtkMultiProcessController* controller, vtkImageData* input,
  const int whole[6], const int needed[6], vtkImageData* fetched, std::string& error)
{
  // One whole extent on every process: the largest of each bound and of its negation.
  int bounds[12], largest[12];
  for (int i = 0; i < 6; ++i)
  {
    bounds[i] = whole[i];
    bounds[6 + i] = -whole[i];
  }
  controller->AllReduce(bounds, largest, 12, vtkCommunicator::MAX_OP);
  for (int i = 0; i < 6; ++i)
  {
    if (largest[i] != -largest[6 + i])
    {
      std::ostringstream why;
      why << "The processes disagree on the whole extent of the input (this one's: " << whole[0]
          << ".." << whole[1] << ", " << whole[2] << ".." << whole[3] << ", " << whole[4] << ".."
          << whole[5] << "): each was handed its piece as if it were the whole volume, and "
          << "the result would be wrong at every piece's border. Give the source the whole "
          << "extent of the data set (in Catalyst, the adaptor's whole extent, e.g. "
          << "bridge.coprocess(..., wholeExtent=...); in VTK, vtkTrivialProducer::SetWholeExtent).";
      error = why.str();
      return nullptr;
    }
  }
  int common[6];
  const bool covered = EmptyExtent(needed) ||
    (input->GetNumberOfPoints() > 0 && IntersectExtents(input->GetExtent(), needed, common) &&
      std::equal(common, common + 6, needed));
  if (GlobalMax(controller, covered ? 0.0 : 1.0) == 0.0)
    return input;
  if (RedistributeExtents(controller, input, needed, fetched))
    return fetched;
  error = "The processes' pieces of the input do not hold every voxel this filter needs: "
          "give it a source that delivers the whole data set across the processes.";
  return nullptr;
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
