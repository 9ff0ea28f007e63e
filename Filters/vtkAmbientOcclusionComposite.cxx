#include "vtkAmbientOcclusionComposite.h"

#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionExtents.h"

#include "vtkAlgorithm.h"
#include "vtkAppendPolyData.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkDataObjectTree.h"
#include "vtkDataObjectTreeIterator.h"
#include "vtkDataObjectTypes.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMatrix3x3.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkPartitionedDataSet.h"
#include "vtkPartitionedDataSetCollection.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <map>
#include <sstream>
#include <vector>

namespace vtkAmbientOcclusionComposite
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

/// One volume: pieces on one grid, in index space of the first piece's origin.
struct Volume
{
  double scope;
  double origin[3], spacing[3], direction[9];
  double arrays;
  int whole[6];
};

/// The composite input's leaves, in traversal order, and its volumes.
struct Volumes
{
  std::vector<vtkDataObject*> leaves;         // every non-empty leaf, in traversal order
  std::vector<int> leafPiece;                 // its index among this process's image pieces, or -1
  std::vector<vtkImageData*> pieces;          // this process's image pieces with voxels
  std::vector<int> pieceVolume;               // the volume of each
  std::vector<std::array<int, 3>> pieceShift; // its extent's shift into the volume's indices
  std::vector<Volume> volumes;
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

/// An iterator over the leaves of `input` that hold something, in traversal order.
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

/// Collective: the volumes of a composite input, the same on every process.
bool FindVolumes(vtkMultiProcessController* controller, vtkCompositeDataSet* input, Volumes& found,
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

/// Collective: volume v gathered as this process's piece of its whole extent, with the
/// input information of an image path that reads it.
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

/// An output information asking for piece `rank` of `ranks` of `whole`.
void AskForPiece(
  vtkInformation* information, vtkDataObject* output, int rank, int ranks, const int whole[6])
{
  int piece[6];
  vtkAmbientOcclusionExtents::PieceOfWhole(rank, ranks, whole, piece);
  information->Set(vtkDataObject::DATA_OBJECT(), output);
  information->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole, 6);
  information->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), piece, 6);
  information->Set(vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER(), rank);
  information->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES(), ranks);
  information->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(), 0);
}

bool ProduceVolumes(vtkMultiProcessController* controller, vtkInformationVector** inputs,
  vtkCompositeDataSet* output, const ImagePath& path, std::string& error);

} // namespace

void AcceptImagesAndComposites(vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkImageData");
  info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkCompositeDataSet");
}

bool IsComposite(vtkInformation* info)
{
  return info && vtkCompositeDataSet::SafeDownCast(info->Get(vtkDataObject::DATA_OBJECT()));
}

void AcceptSurfacesAndComposites(vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkPolyData");
  info->Append(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), "vtkCompositeDataSet");
}

int RequestDataObject(
  vtkInformationVector** inputs, vtkInformationVector* outputs, const char* single)
{
  vtkInformation* inInfo = inputs[0]->GetInformationObject(0);
  vtkInformation* outInfo = outputs->GetInformationObject(0);
  vtkDataObject* input = inInfo ? inInfo->Get(vtkDataObject::DATA_OBJECT()) : nullptr;
  vtkDataObject* output = outInfo->Get(vtkDataObject::DATA_OBJECT());
  const bool composite = vtkCompositeDataSet::SafeDownCast(input) != nullptr;
  const char* type = composite ? input->GetClassName() : single;
  if (output && output->IsA(type))
    return 1;
  vtkSmartPointer<vtkDataObject> made;
  if (composite)
    made.TakeReference(input->NewInstance());
  else
    made.TakeReference(vtkDataObjectTypes::NewDataObject(single));
  outInfo->Set(vtkDataObject::DATA_OBJECT(), made);
  return 1;
}

int ProduceOnSurface(vtkAlgorithm* filter, vtkMultiProcessController* controller,
  vtkInformationVector** inputs, vtkInformationVector* outputs, const ImagePath& path)
{
  vtkInformation* surfaceInfo = inputs[0]->GetInformationObject(0);
  vtkInformation* volumeInfo = inputs[1]->GetInformationObject(0);
  vtkDataObject* output = vtkDataObject::GetData(outputs);
  std::string error;
  auto refuse = [&]
  {
    output->Initialize();
    if (!error.empty())
      vtkErrorWithObjectMacro(filter, << error);
    return 1;
  };
  vtkNew<vtkInformationVector> surfaces, volumes;
  if (IsComposite(volumeInfo))
  {
    Volumes found;
    if (!FindVolumes(controller,
          vtkCompositeDataSet::SafeDownCast(volumeInfo->Get(vtkDataObject::DATA_OBJECT())), found,
          error))
      return refuse();
    if (found.volumes.size() != 1)
    {
      error = "The Volume input holds " + std::to_string(found.volumes.size()) +
        " volumes (pieces on different grids, or none); this filter samples one.";
      return refuse();
    }
    vtkNew<vtkInformation> gathered;
    if (!GatherPiece(controller, found, 0, gathered, error))
      return refuse();
    volumes->Append(gathered);
  }
  else
    volumes->Append(volumeInfo);

  // The surface's blocks as one surface, each block's first point in it.
  auto* composite =
    vtkCompositeDataSet::SafeDownCast(surfaceInfo->Get(vtkDataObject::DATA_OBJECT()));
  std::vector<vtkDataObject*> leaves;
  std::vector<vtkIdType> firsts;
  vtkNew<vtkPolyData> joined;
  if (composite)
  {
    vtkNew<vtkAppendPolyData> append;
    std::string foreign;
    vtkIdType points = 0;
    vtkSmartPointer<vtkCompositeDataIterator> it = LeafIterator(composite);
    for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
    {
      vtkDataObject* leaf = it->GetCurrentDataObject();
      leaves.push_back(leaf);
      firsts.push_back(points);
      auto* polygons = vtkPolyData::SafeDownCast(leaf);
      if (!polygons)
        foreign = leaf->GetClassName();
      else if (polygons->GetNumberOfPoints() > 0)
      {
        append->AddInputData(polygons);
        points += polygons->GetNumberOfPoints();
      }
    }
    if (GlobalMax(controller, foreign.empty() ? 0.0 : 1.0) > 0.0)
    {
      error = "The surface input holds " +
        (foreign.empty() ? std::string("other data than surfaces") : "a " + foreign) +
        " (on some process): give it polygonal data, or a composite data set of it.";
      return refuse();
    }
    if (points > 0)
    {
      append->Update();
      joined->ShallowCopy(append->GetOutput());
    }
    vtkNew<vtkInformation> info;
    info->Set(vtkDataObject::DATA_OBJECT(), joined);
    surfaces->Append(info);
  }
  else
    surfaces->Append(surfaceInfo);

  vtkNew<vtkInformationVector> results;
  vtkNew<vtkPolyData> shaded;
  if (composite)
  {
    vtkNew<vtkInformation> info;
    info->Set(vtkDataObject::DATA_OBJECT(), shaded);
    vtkInformation* asked = outputs->GetInformationObject(0);
    info->CopyEntry(asked, vtkStreamingDemandDrivenPipeline::UPDATE_PIECE_NUMBER());
    info->CopyEntry(asked, vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES());
    results->Append(info);
  }
  vtkInformationVector* in[2] = { surfaces, volumes };
  path(in, composite ? results.Get() : outputs);
  if (!composite)
    return 1;

  // Each block with its points' new arrays.
  auto* out = vtkCompositeDataSet::SafeDownCast(output);
  out->Initialize();
  if (shaded->GetNumberOfPoints() != joined->GetNumberOfPoints())
    return 1; // the filter said why
  out->CopyStructure(composite);
  vtkSmartPointer<vtkCompositeDataIterator> it = LeafIterator(composite);
  size_t leaf = 0;
  for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem(), ++leaf)
  {
    vtkSmartPointer<vtkDataObject> copy;
    copy.TakeReference(leaves[leaf]->NewInstance());
    copy->ShallowCopy(leaves[leaf]);
    auto* block = vtkPolyData::SafeDownCast(copy);
    const vtkIdType n = block->GetNumberOfPoints();
    vtkPointData* arrays = shaded->GetPointData();
    for (int a = 0; n > 0 && a < arrays->GetNumberOfArrays(); ++a)
    {
      vtkDataArray* from = arrays->GetArray(a);
      if (!from)
        continue;
      vtkSmartPointer<vtkDataArray> part;
      part.TakeReference(from->NewInstance());
      part->SetName(from->GetName());
      part->SetNumberOfComponents(from->GetNumberOfComponents());
      part->SetNumberOfTuples(n);
      part->InsertTuples(0, n, firsts[leaf], from);
      block->GetPointData()->AddArray(part);
    }
    vtkFieldData* fields = shaded->GetFieldData();
    for (int a = 0; a < fields->GetNumberOfArrays(); ++a)
      block->GetFieldData()->AddArray(fields->GetAbstractArray(a));
    out->SetDataSet(it, copy);
  }
  return 1;
}

bool ForEachVolume(vtkMultiProcessController* controller, vtkInformation* input,
  const std::function<bool(int, int, vtkInformation*)>& each, std::string& error)
{
  Volumes found;
  if (!FindVolumes(controller,
        vtkCompositeDataSet::SafeDownCast(input->Get(vtkDataObject::DATA_OBJECT())), found, error))
    return false;
  const int volumes = static_cast<int>(found.volumes.size());
  for (int v = 0; v < volumes; ++v)
  {
    vtkNew<vtkInformation> information;
    if (!GatherPiece(controller, found, v, information, error))
      return false;
    const bool done = each(v, volumes, information);
    if (GlobalMax(controller, done ? 0.0 : 1.0) > 0.0)
      return false;
  }
  return true;
}

int ProduceEachVolume(vtkAlgorithm* filter, vtkMultiProcessController* controller,
  vtkInformationVector** inputs, vtkInformationVector* outputs, const ImagePath& path)
{
  auto* output = vtkCompositeDataSet::GetData(outputs);
  std::string error;
  if (!ProduceVolumes(controller, inputs, output, path, error))
  {
    output->Initialize();
    if (!error.empty())
      vtkErrorWithObjectMacro(filter, << error);
  }
  return 1;
}

namespace
{

bool ProduceVolumes(vtkMultiProcessController* controller, vtkInformationVector** inputs,
  vtkCompositeDataSet* output, const ImagePath& path, std::string& error)
{
  auto* input = vtkCompositeDataSet::GetData(inputs[0]);
  output->Initialize();
  Volumes found;
  if (!FindVolumes(controller, input, found, error))
    return false;
  const int rank = controller ? controller->GetLocalProcessId() : 0;
  const int ranks = controller ? controller->GetNumberOfProcesses() : 1;
  // Each input piece with voxels gets the filter's arrays in results[piece].
  std::vector<vtkSmartPointer<vtkImageData>> results(found.pieces.size());
  for (int v = 0; v < static_cast<int>(found.volumes.size()); ++v)
  {
    vtkNew<vtkInformation> inInfo, outInfo;
    if (!GatherPiece(controller, found, v, inInfo, error))
      return false;
    vtkNew<vtkInformationVector> pathInputs, pathOutputs;
    pathInputs->Append(inInfo);
    vtkNew<vtkImageData> computed;
    AskForPiece(outInfo, computed, rank, ranks, found.volumes[v].whole);
    pathOutputs->Append(outInfo);
    vtkInformationVector* inputVectors[1] = { pathInputs };
    path(inputVectors, pathOutputs);
    int piece[6];
    outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), piece);
    const bool failed = !EmptyExtent(piece) && computed->GetNumberOfPoints() == 0;
    if (GlobalMax(controller, failed ? 1.0 : 0.0) > 0.0)
    {
      // The image path said why on the processes where it failed.
      error = failed ? "" : "Another process could not compute its piece (see its message).";
      return false;
    }
    // The results moved onto this process's pieces of the volume.
    std::vector<int> wanted;
    std::vector<size_t> which;
    for (size_t p = 0; p < found.pieces.size(); ++p)
      if (found.pieceVolume[p] == v)
      {
        const int* ext = found.pieces[p]->GetExtent();
        for (int a = 0; a < 3; ++a)
        {
          wanted.push_back(ext[2 * a] + found.pieceShift[p][a]);
          wanted.push_back(ext[2 * a + 1] + found.pieceShift[p][a]);
        }
        which.push_back(p);
        results[p] = vtkSmartPointer<vtkImageData>::New();
      }
    std::vector<vtkImageData*> into;
    for (size_t p : which)
      into.push_back(results[p]);
    vtkImageData* held = computed.Get();
    vtkAmbientOcclusionCollectives::RedistributeExtents(
      controller, std::vector<vtkImageData*>{ held }, wanted, into);
    for (size_t p : which)
      results[p]->GetFieldData()->ShallowCopy(computed->GetFieldData());
  }

  // The input's structure, each image piece with the filter's arrays added.
  output->CopyStructure(input);
  vtkSmartPointer<vtkCompositeDataIterator> it = LeafIterator(input);
  size_t leaf = 0;
  for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem(), ++leaf)
  {
    vtkDataObject* original = found.leaves[leaf];
    vtkSmartPointer<vtkDataObject> copy;
    copy.TakeReference(original->NewInstance());
    copy->ShallowCopy(original);
    const int p = found.leafPiece[leaf];
    if (p >= 0)
    {
      auto* image = vtkImageData::SafeDownCast(copy);
      vtkPointData* arrays = results[p]->GetPointData();
      vtkDataArray* scalars = image->GetPointData()->GetScalars();
      for (int a = 0; a < arrays->GetNumberOfArrays(); ++a)
        image->GetPointData()->AddArray(arrays->GetArray(a));
      if (scalars)
        image->GetPointData()->SetActiveScalars(scalars->GetName());
      vtkFieldData* fields = results[p]->GetFieldData();
      for (int a = 0; a < fields->GetNumberOfArrays(); ++a)
        image->GetFieldData()->AddArray(fields->GetAbstractArray(a));
    }
    output->SetDataSet(it, copy);
  }
  return true;
}

} // namespace

} // namespace vtkAmbientOcclusionComposite
