#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionMemory.h"

#include "vtkAmbientOcclusionExtents.h"

#include "vao/AmbientOcclusion.h"
#include "vao/Validation.h"
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
#include <atomic>
#include <cmath>
#include <limits>
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

template <typename T>
void GatherAll(vtkMultiProcessController* controller, const std::vector<T>& mine, int per,
  std::vector<T>& all, std::vector<int>& owners)
{
  const int ranks = controller ? controller->GetNumberOfProcesses() : 1;
  if (ranks < 2)
  {
    all = mine;
    owners.assign(mine.size() / per, 0);
    return;
  }
  const vtkIdType count = static_cast<vtkIdType>(mine.size());
  std::vector<vtkIdType> counts(ranks), offsets(ranks);
  controller->AllGather(&count, counts.data(), 1);
  vtkIdType total = 0;
  owners.clear();
  for (int r = 0; r < ranks; ++r)
  {
    offsets[r] = total;
    total += counts[r];
    owners.insert(owners.end(), static_cast<size_t>(counts[r] / per), r);
  }
  all.assign(static_cast<size_t>(std::max<vtkIdType>(total, 1)), T());
  controller->AllGatherV(mine.data(), all.data(), count, counts.data(), offsets.data());
  all.resize(static_cast<size_t>(total));
}

/// The bytes of the point arrays of an image (what a message of it carries, less framing).
vtkIdType ArrayBytes(vtkImageData* image)
{
  vtkIdType bytes = 0;
  vtkPointData* data = image->GetPointData();
  for (int a = 0; a < data->GetNumberOfArrays(); ++a)
    if (vtkDataArray* array = data->GetArray(a))
      bytes += array->GetNumberOfValues() * array->GetDataTypeSize();
  return bytes;
}

} // namespace

std::vector<Transfer> PlanTransfers(const std::vector<int>& held,
  const std::vector<int>& heldOwners, const std::vector<int>& wanted,
  const std::vector<int>& wantedOwners, bool& complete)
{
  const int ranks = 1 +
    std::max(heldOwners.empty() ? 0 : *std::max_element(heldOwners.begin(), heldOwners.end()),
      wantedOwners.empty() ? 0 : *std::max_element(wantedOwners.begin(), wantedOwners.end()));
  std::vector<Transfer> plan;
  complete = true;
  for (size_t w = 0; w < wantedOwners.size(); ++w)
  {
    const int to = wantedOwners[w];
    std::vector<Box> remaining;
    if (!EmptyExtent(&wanted[6 * w]))
      remaining.push_back(Box{ { wanted[6 * w], wanted[6 * w + 1], wanted[6 * w + 2],
        wanted[6 * w + 3], wanted[6 * w + 4], wanted[6 * w + 5] } });
    // Its own blocks first (no message), then the others' in rank order.
    for (int k = -1; k < ranks && !remaining.empty(); ++k)
    {
      const int from = k < 0 ? to : k;
      if (k >= 0 && from == to)
        continue;
      for (size_t h = 0; h < heldOwners.size() && !remaining.empty(); ++h)
      {
        if (heldOwners[h] != from || EmptyExtent(&held[6 * h]))
          continue;
        std::vector<Box> next;
        for (const Box& box : remaining)
        {
          Transfer part{ from, to, static_cast<int>(h), static_cast<int>(w), {} };
          if (IntersectExtents(box.ext, &held[6 * h], part.ext))
            plan.push_back(part);
          Subtract(box, &held[6 * h], next);
        }
        remaining.swap(next);
      }
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

namespace
{
std::atomic<vtkIdType> sentBytes{ 0 };
}

vtkIdType BytesSent()
{
  return sentBytes.load();
}

void CountSent(vtkIdType bytes)
{
  sentBytes += bytes;
}

void GatherLists(vtkMultiProcessController* controller, const std::vector<double>& mine, int per,
  std::vector<double>& all, std::vector<int>& owners)
{
  GatherAll(controller, mine, per, all, owners);
}

double GlobalMax(vtkMultiProcessController* controller, double value)
{
  double result = value;
  if (controller && controller->GetNumberOfProcesses() > 1)
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

bool RedistributeExtents(vtkMultiProcessController* controller,
  const std::vector<vtkImageData*>& held, const std::vector<int>& wanted,
  const std::vector<vtkImageData*>& outputs)
{
  const int ranks = controller ? controller->GetNumberOfProcesses() : 1;
  const int rank = controller ? controller->GetLocalProcessId() : 0;
  std::vector<int> myHeld;
  vtkImageData* holder = nullptr; // this process's first block with voxels
  for (vtkImageData* block : held)
  {
    int ext[6] = { 0, -1, 0, -1, 0, -1 };
    if (block && block->GetNumberOfPoints() > 0)
    {
      block->GetExtent(ext);
      holder = holder ? holder : block;
    }
    myHeld.insert(myHeld.end(), ext, ext + 6);
  }
  std::vector<int> heldExtents, heldOwners, wantedExtents, wantedOwners;
  GatherAll(controller, myHeld, 6, heldExtents, heldOwners);
  GatherAll(controller, wanted, 6, wantedExtents, wantedOwners);
  // The grid from a process that holds voxels: a reader that does not split (MetaImage,
  // NRRD) hands the others an empty image without one.
  std::vector<double> mine(15), geometries;
  std::vector<int> geometryOwners;
  if (holder)
  {
    holder->GetOrigin(mine.data());
    holder->GetSpacing(mine.data() + 3);
    std::copy(holder->GetDirectionMatrix()->GetData(), holder->GetDirectionMatrix()->GetData() + 9,
      mine.data() + 6);
  }
  GatherAll(controller, mine, 15, geometries, geometryOwners);
  double geometry[15] = {};
  for (size_t h = 0; h < heldOwners.size(); ++h)
    if (!EmptyExtent(&heldExtents[6 * h]))
    {
      std::copy(&geometries[15 * heldOwners[h]], &geometries[15 * heldOwners[h]] + 15, geometry);
      break;
    }

  for (vtkImageData* output : outputs)
    output->Initialize();
  bool complete = true;
  const std::vector<Transfer> plan =
    PlanTransfers(heldExtents, heldOwners, wantedExtents, wantedOwners, complete);
  if (!complete)
    return false;
  // Index of this process's first held block and first wanted extent in the global lists.
  const int firstHeld =
    static_cast<int>(std::find(heldOwners.begin(), heldOwners.end(), rank) - heldOwners.begin());
  const int firstWanted = static_cast<int>(
    std::find(wantedOwners.begin(), wantedOwners.end(), rank) - wantedOwners.begin());
  auto paste = [&](vtkImageData* piece, const Transfer& part)
  {
    vtkImageData* output = outputs[part.into - firstWanted];
    if (output->GetNumberOfPoints() == 0)
      AllocateWanted(piece, geometry, &wanted[6 * (part.into - firstWanted)], output);
    PasteExtent(piece, part.ext, output); // the transport may not keep the extent
  };
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
            CopyRequestedExtent(held[part.block - firstHeld], piece, part.ext);
            controller->Send(piece.Get(), other, kPieceTag);
            CountSent(ArrayBytes(piece));
          }
      };
      auto receive = [&]
      {
        for (const Transfer& part : plan)
          if (part.to == rank && part.from == other)
          {
            vtkNew<vtkImageData> piece;
            if (other == rank)
              CopyRequestedExtent(held[part.block - firstHeld], piece, part.ext);
            else
              controller->Receive(piece.Get(), other, kPieceTag);
            paste(piece, part);
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

bool RedistributeExtents(vtkMultiProcessController* controller, vtkImageData* held,
  const int wanted[6], vtkImageData* output)
{
  return RedistributeExtents(controller, std::vector<vtkImageData*>{ held },
    std::vector<int>(wanted, wanted + 6), std::vector<vtkImageData*>{ output });
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

vao::MomentBasis WholeMomentBasis(vtkMultiProcessController* controller,
  const vao::VolumeView* volume, const int inputExt[6], const int outExt[6], const int whole[6])
{
  // This process's share: its output piece less the lower processes' pieces.
  const int ranks = controller->GetNumberOfProcesses(), rank = controller->GetLocalProcessId();
  std::vector<int> pieces(static_cast<size_t>(6 * ranks));
  controller->AllGather(outExt, pieces.data(), 6);
  std::vector<Box> share;
  if (volume && !EmptyExtent(outExt))
    share.push_back(Box{ { outExt[0], outExt[1], outExt[2], outExt[3], outExt[4], outExt[5] } });
  for (int r = 0; r < rank && !share.empty(); ++r)
  {
    std::vector<Box> rest;
    for (const Box& box : share)
      Subtract(box, &pieces[6 * r], rest);
    share.swap(rest);
  }
  // Sum and count of the sampled voxels, lowest and highest value (as maxima).
  double local[4] = { 0.0, 0.0, -std::numeric_limits<double>::infinity(),
    -std::numeric_limits<double>::infinity() };
  const vao::Index3 wholeDims{ whole[1] - whole[0] + 1, whole[3] - whole[2] + 1,
    whole[5] - whole[4] + 1 };
  const vao::Index3 offset{ inputExt[0] - whole[0], inputExt[2] - whole[2],
    inputExt[4] - whole[4] };
  for (const Box& box : share)
  {
    vao::Region region;
    for (int a = 0; a < 3; ++a)
    {
      region.begin[a] = box.ext[2 * a] - inputExt[2 * a];
      region.size[a] = box.ext[2 * a + 1] - box.ext[2 * a] + 1;
    }
    const vao::ShiftSamples samples = vao::momentShiftSamples(*volume, region, offset, wholeDims);
    local[0] += samples.sum;
    local[1] += static_cast<double>(samples.count);
  }
  if (volume && !vao::needsValueScan(volume->type))
    share.clear(); // exact integer sums: no basis
  if (!share.empty())
  {
    const std::array<double, 2> range = vao::valueRange(*volume);
    local[2] = -range[0];
    local[3] = range[1];
  }
  double sums[2], extremes[2];
  controller->AllReduce(local, sums, 2, vtkCommunicator::SUM_OP);
  controller->AllReduce(local + 2, extremes, 2, vtkCommunicator::MAX_OP);
  vao::MomentBasis basis;
  if (sums[1] > 0.0 && std::isfinite(extremes[0]) && std::isfinite(extremes[1]))
  {
    basis.shift = sums[0] / sums[1];
    basis.lowest = -extremes[0];
    basis.highest = extremes[1];
  }
  return basis;
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
  CountSent(static_cast<vtkIdType>(mine.size() * sizeof(float)) *
    (controller->GetNumberOfProcesses() - 1)); // each other process receives it
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
