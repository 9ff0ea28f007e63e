#include "vtkAmbientOcclusionComposite.h"

#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionExtents.h"
#include "vtkAmbientOcclusionVolumes.h"

#include "vtkAlgorithm.h"
#include "vtkAppendPolyData.h"
#include "vtkCompositeDataIterator.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkDataObjectTypes.h"
#include "vtkDataSetAttributes.h"
#include "vtkFieldData.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cstring>
#include <functional>
#include <vector>

namespace vtkAmbientOcclusionComposite
{
namespace
{

using vtkAmbientOcclusionCollectives::GlobalMax;
using vtkAmbientOcclusionExtents::EmptyExtent;

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
    vtkAmbientOcclusionVolumes::Volumes found;
    if (!vtkAmbientOcclusionVolumes::Find(controller,
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
    if (!vtkAmbientOcclusionVolumes::GatherPiece(controller, found, 0, gathered, error))
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
    vtkSmartPointer<vtkCompositeDataIterator> it =
      vtkAmbientOcclusionVolumes::LeafIterator(composite);
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
  vtkSmartPointer<vtkCompositeDataIterator> it =
    vtkAmbientOcclusionVolumes::LeafIterator(composite);
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
  vtkAmbientOcclusionVolumes::Volumes found;
  if (!vtkAmbientOcclusionVolumes::Find(controller,
        vtkCompositeDataSet::SafeDownCast(input->Get(vtkDataObject::DATA_OBJECT())), found, error))
    return false;
  const int volumes = static_cast<int>(found.volumes.size());
  for (int v = 0; v < volumes; ++v)
  {
    vtkNew<vtkInformation> information;
    if (!vtkAmbientOcclusionVolumes::GatherPiece(controller, found, v, information, error))
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
  vtkAmbientOcclusionVolumes::Volumes found;
  if (!vtkAmbientOcclusionVolumes::Find(controller, input, found, error))
    return false;
  const int rank = controller ? controller->GetLocalProcessId() : 0;
  const int ranks = controller ? controller->GetNumberOfProcesses() : 1;
  // Each input piece with voxels gets the filter's arrays in results[piece].
  std::vector<vtkSmartPointer<vtkImageData>> results(found.pieces.size());
  for (int v = 0; v < static_cast<int>(found.volumes.size()); ++v)
  {
    vtkNew<vtkInformation> inInfo, outInfo;
    if (!vtkAmbientOcclusionVolumes::GatherPiece(controller, found, v, inInfo, error))
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
  vtkSmartPointer<vtkCompositeDataIterator> it = vtkAmbientOcclusionVolumes::LeafIterator(input);
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
      // Every array of the result but the ghost flags: where pieces overlap, the voxels came
      // from one of them, with its flags; each piece keeps its own.
      for (int a = 0; a < arrays->GetNumberOfArrays(); ++a)
        if (arrays->GetArrayName(a) &&
          strcmp(arrays->GetArrayName(a), vtkDataSetAttributes::GhostArrayName()) != 0)
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
