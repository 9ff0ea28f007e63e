#include "vtkAmbientOcclusionThresholds.h"

#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionExtents.h"

#include "vao/HistogramCdf.h"
#include "vao/Validation.h"

#include "vtkAlgorithm.h"
#include "vtkCommunicator.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationObjectBaseKey.h"
#include "vtkInformationVector.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <limits>

namespace vtkAmbientOcclusionThresholds
{
namespace
{

/// Sums the counts and combines the extrema of every process's summary.
void Reduce(vtkMultiProcessController* controller, vao::ValueHistogram& histogram)
{
  const vtkIdType cells = static_cast<vtkIdType>(histogram.counts.size());
  std::vector<long long> local(histogram.counts.begin(), histogram.counts.end()),
    total(local.size());
  controller->AllReduce(local.data(), total.data(), cells, vtkCommunicator::SUM_OP);
  std::copy(total.begin(), total.end(), histogram.counts.begin());
  std::vector<double> reduced(histogram.minimum.size());
  controller->AllReduce(histogram.minimum.data(), reduced.data(), cells, vtkCommunicator::MIN_OP);
  histogram.minimum = reduced;
  controller->AllReduce(histogram.maximum.data(), reduced.data(), cells, vtkCommunicator::MAX_OP);
  histogram.maximum = reduced;
}

} // namespace

std::vector<std::vector<int>> SubtractExtents(
  const int ext[6], const std::vector<const int*>& others)
{
  std::vector<std::vector<int>> boxes;
  if (!vtkAmbientOcclusionExtents::EmptyExtent(ext))
  {
    boxes.emplace_back(ext, ext + 6);
  }
  for (const int* other : others)
  {
    std::vector<std::vector<int>> next;
    for (std::vector<int> box : boxes)
    {
      int common[6];
      if (!vtkAmbientOcclusionExtents::IntersectExtents(box.data(), other, common))
      {
        next.push_back(box);
        continue;
      }
      // Peel the parts of the box outside `common`, one axis at a time.
      for (int a = 0; a < 3; ++a)
      {
        if (box[2 * a] < common[2 * a])
        {
          std::vector<int> below = box;
          below[2 * a + 1] = common[2 * a] - 1;
          next.push_back(below);
          box[2 * a] = common[2 * a];
        }
        if (box[2 * a + 1] > common[2 * a + 1])
        {
          std::vector<int> above = box;
          above[2 * a] = common[2 * a + 1] + 1;
          next.push_back(above);
          box[2 * a + 1] = common[2 * a + 1];
        }
      }
    }
    boxes.swap(next);
  }
  return boxes;
}

namespace
{

/// Pass 1, which voxels this process counts: the boxes of its output extent that no lower
/// process's output extent holds, so that each voxel is counted once, by the lowest process
/// whose output extent holds it. Collective (`controller` null: one process). False when
/// any process failed before.
bool OwnedBoxes(vtkMultiProcessController* controller, const Piece& piece,
  std::vector<std::vector<int>>& owned, std::string& error)
{
  const bool holds = piece.volume && !piece.failed;
  int mine[6] = { 0, -1, 0, -1, 0, -1 };
  if (holds)
  {
    std::copy(piece.outExt, piece.outExt + 6, mine);
  }
  std::vector<int> all(mine, mine + 6);
  if (controller)
  {
    all.resize(6 * static_cast<size_t>(controller->GetNumberOfProcesses()));
    controller->AllGather(mine, all.data(), 6);
    if (vtkAmbientOcclusionCollectives::GlobalMax(controller, piece.failed ? 1.0 : 0.0) > 0.0)
    {
      if (!piece.failed)
        error = "Histogram CDF: another process failed, so the thresholds of the whole data set "
                "are unknown.";
      return false;
    }
  }
  if (piece.failed)
  {
    return false;
  }
  std::vector<const int*> lower;
  const int rank = controller ? controller->GetLocalProcessId() : 0;
  for (int r = 0; r < rank; ++r)
  {
    lower.push_back(&all[6 * static_cast<size_t>(r)]);
  }
  owned = SubtractExtents(mine, lower);
  return true;
}

/// Pass 2, the histogram's cells: they span the value range of every process's owned
/// voxels and depend on the type (integers get one cell per value), which the processes
/// agree on. Collective. False when no process holds any voxel.
bool HistogramCells(vtkMultiProcessController* controller, const Piece& piece,
  const std::vector<std::vector<int>>& owned, vao::ValueHistogram& histogram, std::string& error)
{
  double range[2] = { std::numeric_limits<double>::infinity(),
    -std::numeric_limits<double>::infinity() };
  if (piece.volume && !owned.empty())
  {
    range[0] = piece.scan->minimum;
    range[1] = piece.scan->maximum;
  }
  // The type from a process that has data: the same array everywhere.
  double type = piece.volume ? static_cast<double>(piece.volume->type) : -1.0;
  if (controller)
  {
    vtkAmbientOcclusionCollectives::GlobalRange(controller, range);
    type = vtkAmbientOcclusionCollectives::GlobalMax(controller, type);
  }
  if (!(range[0] <= range[1]) || type < 0.0)
  {
    error = "Histogram CDF: no process holds any voxel of the data set.";
    return false;
  }
  histogram = vao::ValueHistogram::forRange(
    static_cast<vao::ScalarType>(static_cast<int>(type)), range[0], range[1]);
  return true;
}

/// Pass 3, the counts: this process's owned voxels into the histogram, then the sum of
/// every process's. Collective: a failure on any process fails every one.
bool CountOwnedVoxels(vtkMultiProcessController* controller, const Piece& piece,
  const std::vector<std::vector<int>>& owned, vao::ValueHistogram& histogram, std::string& error)
{
  bool failed = false;
  for (const auto& box : owned)
  {
    vao::Region region;
    for (int a = 0; a < 3; ++a)
    {
      region.begin[a] = box[2 * a] - piece.inExt[2 * a];
      region.size[a] = box[2 * a + 1] - box[2 * a] + 1;
    }
    const vao::Status status = vao::addToValueHistogram(*piece.volume, region, histogram);
    if (!status.ok)
    {
      if (!status.aborted)
        error = "Histogram CDF's value histogram failed: " + status.message + ".";
      failed = true;
      break;
    }
  }
  if (!controller)
  {
    return !failed;
  }
  if (vtkAmbientOcclusionCollectives::GlobalMax(controller, failed ? 1.0 : 0.0) > 0.0)
  {
    if (error.empty())
      error = "Histogram CDF: another process failed, so the thresholds of the whole data set are "
              "unknown.";
    return false;
  }
  Reduce(controller, histogram);
  return true;
}

/// Pass 4, the check: the processes' output extents together cover the whole extent, so
/// that the thresholds are the whole data set's.
bool CoversWholeExtent(const vao::ValueHistogram& histogram, const int whole[6], std::string& error)
{
  const long long counted = histogram.totalCount();
  const long long expected = vtkAmbientOcclusionExtents::ExtentPoints(whole);
  if (counted != expected)
  {
    error = "Histogram CDF takes its thresholds from every voxel of the data set, but the "
            "processes' pieces hold " +
      std::to_string(counted) + " of its " + std::to_string(expected) +
      " voxels: request the whole extent, or pieces that cover it.";
    return false;
  }
  return true;
}

} // namespace

bool Compute(vtkMultiProcessController* controller, const Piece& piece, int bins,
  std::vector<double>& thresholds, std::string& error)
{
  const int ranks = controller ? controller->GetNumberOfProcesses() : 1;
  if (ranks <= 1)
  {
    controller = nullptr; // one process: nothing to exchange
  }
  std::vector<std::vector<int>> owned;
  vao::ValueHistogram histogram;
  if (!OwnedBoxes(controller, piece, owned, error) ||
    !HistogramCells(controller, piece, owned, histogram, error) ||
    !CountOwnedVoxels(controller, piece, owned, histogram, error) ||
    !CoversWholeExtent(histogram, piece.whole, error))
  {
    return false;
  }
  thresholds = vao::histogramThresholds(histogram, bins);
  return true;
}

namespace
{
/// The array's kept thresholds: its MTime, the component and the bins, then the values. An
/// object key, which VTK's writers do not save with the array (a number key would be).
vtkInformationObjectBaseKey* KeptThresholds()
{
  static vtkInformationObjectBaseKey* const key = new vtkInformationObjectBaseKey(
    "HISTOGRAM_THRESHOLDS", "vtkAmbientOcclusionThresholds", "vtkDoubleArray");
  return key;
}
constexpr vtkIdType kHead = 3;
} // namespace

bool Recall(vtkDataArray* array, int component, int bins, std::vector<double>& thresholds)
{
  vtkInformation* info = array && array->HasInformation() ? array->GetInformation() : nullptr;
  auto* kept = info ? vtkDoubleArray::SafeDownCast(info->Get(KeptThresholds())) : nullptr;
  if (!kept || kept->GetNumberOfValues() < kHead ||
    kept->GetValue(0) != static_cast<double>(array->GetMTime()) || kept->GetValue(1) != component ||
    kept->GetValue(2) != bins)
    return false;
  thresholds.assign(kept->GetPointer(kHead), kept->GetPointer(0) + kept->GetNumberOfValues());
  return true;
}

void Remember(vtkDataArray* array, int component, int bins, const std::vector<double>& thresholds)
{
  if (!array)
    return;
  vtkNew<vtkDoubleArray> kept;
  kept->InsertNextValue(static_cast<double>(array->GetMTime()));
  kept->InsertNextValue(component);
  kept->InsertNextValue(bins);
  for (const double t : thresholds)
    kept->InsertNextValue(t);
  array->GetInformation()->Set(KeptThresholds(), kept);
}

bool ComputeInSlabs(vtkAlgorithm* producer, int port, int slabs, int bins,
  const std::function<bool(vtkImageData*, vao::VolumeView&, std::string&)>& view,
  std::vector<double>& thresholds, std::string& error)
{
  producer->UpdateInformation();
  int whole[6];
  producer->GetOutputInformation(port)->Get(
    vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  const int nz = whole[5] - whole[4] + 1;
  if (vtkAmbientOcclusionExtents::EmptyExtent(whole))
  {
    error = "the input is empty";
    return false;
  }
  slabs = std::max(1, std::min(slabs, nz));
  double range[2] = { std::numeric_limits<double>::infinity(),
    -std::numeric_limits<double>::infinity() };
  vao::ValueHistogram histogram;
  // Pass 0: the range (it fixes the cells); pass 1: the histogram of each slab.
  for (int pass = 0; pass < 2; ++pass)
  {
    for (int s = 0; s < slabs; ++s)
    {
      int slab[6] = { whole[0], whole[1], whole[2], whole[3], whole[4] + nz * s / slabs,
        whole[4] + nz * (s + 1) / slabs - 1 };
      vtkNew<vtkInformationVector> requests;
      vtkNew<vtkInformation> request;
      request->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), slab, 6);
      requests->Append(request);
      producer->Update(port, requests);
      vtkImageData* image = vtkImageData::SafeDownCast(producer->GetOutputDataObject(port));
      vao::VolumeView volume;
      int common[6];
      if (!image ||
        !vtkAmbientOcclusionExtents::IntersectExtents(image->GetExtent(), slab, common) ||
        !std::equal(common, common + 6, slab))
      {
        error = "the input did not deliver the slab z = " + std::to_string(slab[4]) + ".." +
          std::to_string(slab[5]);
        return false;
      }
      if (!view(image, volume, error))
      {
        return false;
      }
      vao::Region region;
      for (int a = 0; a < 3; ++a)
      {
        region.begin[a] = slab[2 * a] - image->GetExtent()[2 * a];
        region.size[a] = slab[2 * a + 1] - slab[2 * a] + 1;
      }
      if (pass == 0)
      {
        const vao::ValueScan scan = vao::scanValues(volume);
        const vao::Status finite = vao::finiteStatus(scan);
        if (!finite.ok)
        {
          error = "the slab z = " + std::to_string(slab[4]) + ".." + std::to_string(slab[5]) +
            " holds " + std::to_string(finite.nonFiniteCount) + " NaN or infinite values";
          return false;
        }
        range[0] = std::min(range[0], scan.minimum);
        range[1] = std::max(range[1], scan.maximum);
        if (s + 1 == slabs)
          histogram = vao::ValueHistogram::forRange(volume.type, range[0], range[1]);
        continue;
      }
      const vao::Status status = vao::addToValueHistogram(volume, region, histogram);
      if (!status.ok)
      {
        error = status.message;
        return false;
      }
    }
  }
  // The slabs tile the whole extent: every voxel was counted once.
  thresholds = vao::histogramThresholds(histogram, bins);
  return true;
}

} // namespace vtkAmbientOcclusionThresholds
