#include "vtkAmbientOcclusionVolumes.h"

#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionExtents.h"

#include "vtkAlgorithm.h"
#include "vtkCompositeDataIterator.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkDataObjectTreeIterator.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkMatrix3x3.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkPartitionedDataSet.h"
#include "vtkPartitionedDataSetCollection.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>

namespace vtkAmbientOcclusionVolumes
{
namespace
{

using vtkAmbientOcclusionCollectives::GlobalMax;
using vtkAmbientOcclusionExtents::EmptyExtent;

/// What every process learns of each image piece: its data set (the partitioned data set
/// of a collection, else 0), grid, extent and a digest of its point arrays.
enum Field
{
  kScope = 0,
  kOrigin = 1,
  kSpacing = 4,
  kDirection = 7,
  kExtent = 16,
  kArrays = 22,
  kFields = 23
};

/// A digest of the names, types and components of the point arrays: pieces of one volume
/// must carry the same arrays.
double ArraysDigest(vtkImageData* image)
{
  std::string signature;
  vtkPointData* data = image->GetPointData();
  for (int a = 0; a < data->GetNumberOfArrays(); ++a)
    if (vtkDataArray* array = data->GetArray(a))
      signature += std::string(array->GetName() ? array->GetName() : "") + "/" +
        std::to_string(array->GetDataType()) + "/" +
        std::to_string(array->GetNumberOfComponents()) + ";";
  return static_cast<double>(std::hash<std::string>()(signature) & 0xFFFFFFFFull);
}

bool Close(double a, double b, double tolerance)
{
  return std::fabs(a - b) <= tolerance * std::max({ 1.0, std::fabs(a), std::fabs(b) });
}

/// Whether a piece (its gathered fields) lies on the volume's grid; `shift` then moves
/// its extent into the volume's index space.
bool OnGrid(const double* piece, const Volume& volume, int shift[3])
{
  if (piece[kScope] != volume.scope)
    return false;
  for (int i = 0; i < 3; ++i)
    if (!Close(piece[kSpacing + i], volume.spacing[i], 1e-6))
      return false;
  for (int i = 0; i < 9; ++i)
    if (!Close(piece[kDirection + i], volume.direction[i], 1e-6))
      return false;
  for (int a = 0; a < 3; ++a)
  {
    // Column a of the direction matrix is index axis a in the world.
    double along = 0.0;
    for (int i = 0; i < 3; ++i)
      along += (piece[kOrigin + i] - volume.origin[i]) * volume.direction[3 * i + a];
    const double steps = along / volume.spacing[a];
    if (!std::isfinite(steps) || std::fabs(steps - std::round(steps)) > 1e-3 ||
      std::fabs(steps) > 1e9)
      return false;
    shift[a] = static_cast<int>(std::round(steps));
  }
  return true;
}

/// The leaves of `input` in traversal order, and the partitioned data set of each leaf of
/// a collection.
void ListLeaves(vtkCompositeDataSet* input, std::vector<vtkDataObject*>& leaves,
  std::map<vtkDataObject*, int>& scopes)
{
  if (auto* collection = vtkPartitionedDataSetCollection::SafeDownCast(input))
    for (unsigned int i = 0; i < collection->GetNumberOfPartitionedDataSets(); ++i)
      if (vtkPartitionedDataSet* set = collection->GetPartitionedDataSet(i))
        for (unsigned int j = 0; j < set->GetNumberOfPartitions(); ++j)
          if (vtkDataObject* leaf = set->GetPartitionAsDataObject(j))
            scopes[leaf] = static_cast<int>(i);
  vtkSmartPointer<vtkCompositeDataIterator> it = LeafIterator(input);
  for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
    leaves.push_back(it->GetCurrentDataObject());
}

/// This process's pieces of volume v, as images in the volume's index space (shallow).
std::vector<vtkSmartPointer<vtkImageData>> PiecesOf(const Volumes& found, int v)
{
  std::vector<vtkSmartPointer<vtkImageData>> held;
  for (size_t p = 0; p < found.pieces.size(); ++p)
    if (found.pieceVolume[p] == v)
    {
      auto image = vtkSmartPointer<vtkImageData>::New();
      image->ShallowCopy(found.pieces[p]);
      int ext[6];
      found.pieces[p]->GetExtent(ext);
      for (int a = 0; a < 3; ++a)
      {
        ext[2 * a] += found.pieceShift[p][a];
        ext[2 * a + 1] += found.pieceShift[p][a];
      }
      image->SetExtent(ext);
      image->SetOrigin(const_cast<double*>(found.volumes[v].origin));
      held.push_back(image);
    }
  return held;
}

std::vector<vtkImageData*> Raw(const std::vector<vtkSmartPointer<vtkImageData>>& images)
{
  std::vector<vtkImageData*> raw;
  for (const auto& image : images)
    raw.push_back(image);
  return raw;
}

} // namespace

vtkSmartPointer<vtkCompositeDataIterator> LeafIterator(vtkCompositeDataSet* input)
{
  vtkSmartPointer<vtkCompositeDataIterator> it;
  it.TakeReference(input->NewIterator());
  if (auto* tree = vtkDataObjectTreeIterator::SafeDownCast(it))
  {
    tree->VisitOnlyLeavesOn();
    tree->TraverseSubTreeOn();
  }
  it->SkipEmptyNodesOn();
  return it;
}

bool Find(vtkMultiProcessController* controller, vtkCompositeDataSet* input, Volumes& found,
  std::string& error)
{
  std::map<vtkDataObject*, int> scopes;
  ListLeaves(input, found.leaves, scopes);
  std::vector<double> mine;
  std::string foreign;
  for (vtkDataObject* leaf : found.leaves)
  {
    auto* image = vtkImageData::SafeDownCast(leaf);
    found.leafPiece.push_back(
      image && image->GetNumberOfPoints() > 0 ? static_cast<int>(found.pieces.size()) : -1);
    if (!image)
    {
      foreign = leaf->GetClassName();
      continue;
    }
    if (image->GetNumberOfPoints() == 0)
      continue;
    found.pieces.push_back(image);
    double fields[kFields];
    fields[kScope] = scopes.count(leaf) ? scopes[leaf] : 0;
    image->GetOrigin(fields + kOrigin);
    image->GetSpacing(fields + kSpacing);
    std::copy(image->GetDirectionMatrix()->GetData(), image->GetDirectionMatrix()->GetData() + 9,
      fields + kDirection);
    for (int i = 0; i < 6; ++i)
      fields[kExtent + i] = image->GetExtent()[i];
    fields[kArrays] = ArraysDigest(image);
    mine.insert(mine.end(), fields, fields + kFields);
  }
  if (GlobalMax(controller, foreign.empty() ? 0.0 : 1.0) > 0.0)
  {
    error = "The composite input holds " +
      (foreign.empty() ? std::string("other data than images") : "a " + foreign) +
      " (on some process): this filter computes on images; give it image data, or a "
      "composite data set whose blocks are all images.";
    return false;
  }
  std::vector<double> all;
  std::vector<int> owners;
  vtkAmbientOcclusionCollectives::GatherLists(controller, mine, kFields, all, owners);
  const int rank = controller ? controller->GetLocalProcessId() : 0;
  for (size_t p = 0; p < owners.size(); ++p)
  {
    const double* piece = &all[kFields * p];
    int shift[3] = { 0, 0, 0 };
    size_t v = 0;
    while (v < found.volumes.size() && !OnGrid(piece, found.volumes[v], shift))
      ++v;
    if (v == found.volumes.size())
    {
      Volume volume;
      volume.scope = piece[kScope];
      std::copy(piece + kOrigin, piece + kOrigin + 3, volume.origin);
      std::copy(piece + kSpacing, piece + kSpacing + 3, volume.spacing);
      std::copy(piece + kDirection, piece + kDirection + 9, volume.direction);
      volume.arrays = piece[kArrays];
      for (int a = 0; a < 3; ++a)
      {
        volume.whole[2 * a] = static_cast<int>(piece[kExtent + 2 * a]);
        volume.whole[2 * a + 1] = static_cast<int>(piece[kExtent + 2 * a + 1]);
      }
      found.volumes.push_back(volume);
    }
    Volume& volume = found.volumes[v];
    if (piece[kArrays] != volume.arrays)
    {
      error = "Pieces of one volume (one grid) carry different point arrays: every piece "
              "needs the same arrays (names, types and components).";
      return false;
    }
    for (int a = 0; a < 3; ++a)
    {
      volume.whole[2 * a] =
        std::min(volume.whole[2 * a], static_cast<int>(piece[kExtent + 2 * a]) + shift[a]);
      volume.whole[2 * a + 1] =
        std::max(volume.whole[2 * a + 1], static_cast<int>(piece[kExtent + 2 * a + 1]) + shift[a]);
    }
    if (owners[p] == rank)
    {
      found.pieceVolume.push_back(static_cast<int>(v));
      found.pieceShift.push_back({ shift[0], shift[1], shift[2] });
    }
  }
  // In the collection's order (then in the order first met): the same whichever process
  // holds which pieces.
  std::vector<int> order(found.volumes.size()), rankOf(found.volumes.size());
  for (size_t v = 0; v < order.size(); ++v)
    order[v] = static_cast<int>(v);
  std::stable_sort(order.begin(), order.end(),
    [&](int a, int b) { return found.volumes[a].scope < found.volumes[b].scope; });
  std::vector<Volume> sorted;
  for (size_t v = 0; v < order.size(); ++v)
  {
    rankOf[order[v]] = static_cast<int>(v);
    sorted.push_back(found.volumes[order[v]]);
  }
  found.volumes.swap(sorted);
  for (int& v : found.pieceVolume)
    v = rankOf[v];
  return true;
}

bool GatherPiece(vtkMultiProcessController* controller, const Volumes& found, int v,
  vtkInformation* information, std::string& error)
{
  const Volume& volume = found.volumes[v];
  const int rank = controller ? controller->GetLocalProcessId() : 0;
  const int ranks = controller ? controller->GetNumberOfProcesses() : 1;
  int piece[6];
  vtkAmbientOcclusionExtents::PieceOfWhole(rank, ranks, volume.whole, piece);
  const auto held = PiecesOf(found, v);
  vtkNew<vtkImageData> gathered;
  if (!vtkAmbientOcclusionCollectives::RedistributeExtents(
        controller, Raw(held), std::vector<int>(piece, piece + 6), { gathered.Get() }))
  {
    const int* w = volume.whole;
    std::ostringstream why;
    why << "The pieces of a volume in the composite input leave voxels of its bounding extent ("
        << w[0] << ".." << w[1] << ", " << w[2] << ".." << w[3] << ", " << w[4] << ".." << w[5]
        << ") without a value: the pieces on one grid must fill it.";
    error = why.str();
    return false;
  }
  if (EmptyExtent(piece))
  {
    gathered->SetOrigin(const_cast<double*>(volume.origin));
    gathered->SetSpacing(const_cast<double*>(volume.spacing));
    gathered->SetDirectionMatrix(const_cast<double*>(volume.direction));
  }
  information->Set(vtkDataObject::DATA_OBJECT(), gathered);
  information->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), volume.whole, 6);
  information->Set(vtkDataObject::ORIGIN(), volume.origin, 3);
  information->Set(vtkDataObject::SPACING(), volume.spacing, 3);
  information->Set(vtkDataObject::DIRECTION(), volume.direction, 9);
  information->Set(vtkAlgorithm::CAN_PRODUCE_SUB_EXTENT(), 0);
  return true;
}

} // namespace vtkAmbientOcclusionVolumes
