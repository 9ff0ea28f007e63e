#include "vtkOcclusionSweeping.h"

#include "vtkAmbientOcclusionMemory.h"
#include "vtkAmbientOcclusionRequest.h"

#include "vtkAmbientOcclusionArrayInput.h"
#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionComposite.h"
#include "vtkAmbientOcclusionExtents.h"

#include "vao/BlockSweeping.h"
#include "vao/OcclusionSweeping.h"

#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkOcclusionSweeping);
vtkCxxSetSmartPointerMacro(vtkOcclusionSweeping, Controller, vtkMultiProcessController);

using vtkAmbientOcclusionArrayInput::KernelError;
using vtkAmbientOcclusionArrayInput::PrepareScalars;
using vtkAmbientOcclusionArrayInput::ScalarVolume;
using vtkAmbientOcclusionCollectives::GlobalMax;
using vtkAmbientOcclusionRequest::Execution;

namespace
{

/// The axis along which the processes split the volume into slabs: the longest (z on a
/// tie, the usual slice axis).
int SlabAxis(const int whole[6])
{
  int axis = 2;
  for (int a = 1; a >= 0; --a)
    if (whole[2 * a + 1] - whole[2 * a] > whole[2 * axis + 1] - whole[2 * axis])
      axis = a;
  return axis;
}

/// The slab of process `rank` of `ranks`: the whole extent with the slab axis cut evenly.
void SlabExtent(const int whole[6], int rank, int ranks, int slab[6])
{
  std::copy(whole, whole + 6, slab);
  const int axis = SlabAxis(whole);
  const long long n = whole[2 * axis + 1] - whole[2 * axis] + 1;
  slab[2 * axis] = whole[2 * axis] + static_cast<int>(n * rank / ranks);
  slab[2 * axis + 1] = whole[2 * axis] + static_cast<int>(n * (rank + 1) / ranks) - 1;
}

/// The slab grown by the one ghost layer of scalars that the block sweeper reads across
/// each face with a neighbour.
void SlabInputExtent(const int whole[6], int rank, int ranks, int ext[6])
{
  SlabExtent(whole, rank, ranks, ext);
  const int axis = SlabAxis(whole);
  ext[2 * axis] = std::max(whole[2 * axis], ext[2 * axis] - 1);
  ext[2 * axis + 1] = std::min(whole[2 * axis + 1], ext[2 * axis + 1] + 1);
}

/// The rounds stop when no ghost value moves by this much; so does each round's sweeping
/// of its slab (one pass per round would need as many rounds as passes): the
/// ConvergenceTolerance, or when it is 0 a thousandth of the smallest spacing.
double ExchangeTolerance(double convergenceTolerance, const double spacing[3])
{
  return convergenceTolerance > 0.0 ? convergenceTolerance
                                    : 1e-3 * std::min({ spacing[0], spacing[1], spacing[2] });
}

/// Exchanges the face buffers with the slab neighbours (rank - 1 across the lower face,
/// rank + 1 across the upper). Pairs go in rank order, the lower one sending first, so no
/// two processes wait on each other. Returns the largest change of a ghost value here.
double ExchangeFaces(vtkMultiProcessController* controller, vao::BlockSweeper& block, int axis)
{
  const int rank = controller->GetLocalProcessId();
  constexpr int kFaceTag = 7101;
  double change = 0.0;
  for (int face : { 2 * axis, 2 * axis + 1 }) // the pair below first, then the pair above
  {
    const vtkIdType count = block.faceValueCount(face);
    if (count == 0)
    {
      continue;
    }
    const int neighbour = (face & 1) ? rank + 1 : rank - 1;
    std::vector<float> out(static_cast<std::size_t>(count)), in(static_cast<std::size_t>(count));
    block.exportFace(face, out.data());
    vtkAmbientOcclusionCollectives::CountSent(count * static_cast<vtkIdType>(sizeof(float)));
    if (face & 1) // the lower of the pair
    {
      controller->Send(out.data(), count, neighbour, kFaceTag);
      controller->Receive(in.data(), count, neighbour, kFaceTag);
    }
    else
    {
      controller->Receive(in.data(), count, neighbour, kFaceTag);
      controller->Send(out.data(), count, neighbour, kFaceTag);
    }
    change = std::max(change, block.importFace(face, in.data()));
  }
  return change;
}

/// Adds the float arrays of the outputs to `image` (one tuple per point) and returns
/// where the kernel writes them.
vao::SweepOutput AddOutputArrays(vtkImageData* image, bool withOctants)
{
  auto add = [image](const char* name, int components)
  {
    vtkNew<vtkFloatArray> array;
    array->SetName(name);
    array->SetNumberOfComponents(components);
    vtkAmbientOcclusionMemory::Allocate(
      array, image->GetNumberOfPoints(), std::string("the ") + name + " output");
    image->GetPointData()->AddArray(array);
    return array->GetPointer(0);
  };
  vao::SweepOutput output;
  output.signedDistance = add("SignedDistance", 1);
  output.ambientOcclusion = add("AmbientOcclusion", 1);
  output.octantVisibility = withOctants ? add("OctantVisibility", 8) : nullptr;
  return output;
}

} // namespace

struct vtkOcclusionSweeping::Slab
{
  int extent[6];        // the voxels this process sweeps (its input has a ghost layer more)
  ScalarVolume scalars; // read by the block sweeper until it finishes
  std::unique_ptr<vao::BlockSweeper> block;
};

//------------------------------------------------------------------------------
vtkOcclusionSweeping::vtkOcclusionSweeping()
  : Controller(vtkMultiProcessController::GetGlobalController())
{
  this->SetInputArrayToProcess(
    0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

vtkOcclusionSweeping::~vtkOcclusionSweeping() = default;

vtkMultiProcessController* vtkOcclusionSweeping::GetController() const
{
  return this->Controller;
}

//------------------------------------------------------------------------------
vao::SweepParameters vtkOcclusionSweeping::Parameters() const
{
  vao::SweepParameters parameters;
  parameters.isoValue = this->IsoValue;
  parameters.insideIsAbove = this->InsideIsAbove != 0;
  parameters.iterations = this->NumberOfIterations;
  parameters.tolerance = this->ConvergenceTolerance;
  for (int s = 0; s < 8; ++s)
  {
    parameters.octantMask[s] = this->OctantMask[s] != 0;
  }
  parameters.useGeometryTerm = this->UseGeometryTerm != 0;
  parameters.gamma = this->Gamma;
  parameters.opacity = this->Opacity;
  return parameters;
}

//------------------------------------------------------------------------------
bool vtkOcclusionSweeping::IsDistributed(const int whole[6]) const
{
  // Slabs of at least two voxels; a smaller volume is swept whole by every process.
  const int ranks = this->Controller ? this->Controller->GetNumberOfProcesses() : 1;
  const int axis = SlabAxis(whole);
  return ranks > 1 && whole[2 * axis + 1] - whole[2 * axis] + 1 >= 2 * ranks;
}

//------------------------------------------------------------------------------
vtkTypeBool vtkOcclusionSweeping::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // The output is like the input: an image, or a composite data set of images.
  if (request->Has(vtkDemandDrivenPipeline::REQUEST_DATA_OBJECT()))
    return vtkAmbientOcclusionComposite::RequestDataObject(
      inputVector, outputVector, "vtkImageData");
  return this->Superclass::ProcessRequest(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------
int vtkOcclusionSweeping::FillInputPortInformation(int, vtkInformation* info)
{
  vtkAmbientOcclusionComposite::AcceptImagesAndComposites(info);
  return 1;
}

//------------------------------------------------------------------------------
int vtkOcclusionSweeping::FillOutputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkDataObject"); // made by ProcessRequest
  return 1;
}

//------------------------------------------------------------------------------
int vtkOcclusionSweeping::RequestInformation(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (vtkAmbientOcclusionComposite::IsComposite(inputVector[0]->GetInformationObject(0)))
    return 1; // each volume's pieces are where the composite data set has them
  // Any piece can be produced, from the whole volume (see RequestUpdateExtent).
  outputVector->GetInformationObject(0)->Set(CAN_PRODUCE_SUB_EXTENT(), 1);
  return 1;
}

//------------------------------------------------------------------------------
int vtkOcclusionSweeping::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // Sweeping is global: an occluder anywhere shadows everything behind it. One process
  // sweeps the whole volume; several sweep a slab each (plus its ghost layer).
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  if (vtkAmbientOcclusionComposite::IsComposite(inInfo))
    return 1; // the piece request passes on as it is
  int whole[6];
  inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  if (this->IsDistributed(whole))
  {
    int ext[6];
    const int rank = this->Controller->GetLocalProcessId(),
              ranks = this->Controller->GetNumberOfProcesses();
    SlabInputExtent(whole, rank, ranks, ext);
    if (vtkAmbientOcclusionExtents::CanProduceSubExtent(inInfo))
      vtkAmbientOcclusionExtents::RequestExactExtent(inInfo, ext);
    else // RequestDistributedData fetches the slab from the process that read the file
      vtkAmbientOcclusionExtents::RequestPieceOfWhole(inInfo, rank, ranks);
  }
  else
  {
    vtkAmbientOcclusionExtents::RequestWholeExtent(inInfo);
  }
  return 1;
}

//------------------------------------------------------------------------------
void vtkOcclusionSweeping::WarnNoSurface(const std::string& arrayName)
{
  vtkWarningMacro(<< "IsoValue " << this->IsoValue << " does not cross array '" << arrayName
                  << "': there is no surface; every voxel is "
                  << "entirely inside or outside (AmbientOcclusion 0 or 1).");
}

//------------------------------------------------------------------------------
int vtkOcclusionSweeping::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (vtkAmbientOcclusionComposite::IsComposite(inputVector[0]->GetInformationObject(0)))
    return vtkAmbientOcclusionComposite::ProduceEachVolume(this, this->Controller, inputVector,
      outputVector,
      [&](vtkInformationVector** in, vtkInformationVector* out)
      { return this->RequestData(nullptr, in, out); });
  return vtkAmbientOcclusionRequest::ProduceOutput(this, outputVector,
    "use more MPI ranks, turn OutputOctantVisibility off, or crop or resample the volume.",
    [&] { return this->ProduceOutput(inputVector, outputVector); });
}

//------------------------------------------------------------------------------
int vtkOcclusionSweeping::ProduceOutput(
  vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* input = vtkImageData::GetData(inputVector[0]);
  vtkImageData* output = vtkImageData::GetData(outputVector);
  output->Initialize();
  if (!input)
  {
    return 1;
  }
  int whole[6], outExt[6];
  std::string error = vtkAmbientOcclusionRequest::ThreadsError(this->NumberOfThreads);
  if (!error.empty() ||
    !vtkAmbientOcclusionExtents::WholeAndRequestedExtent(
      inputVector[0], outputVector, whole, outExt, error))
  {
    vtkErrorMacro(<< error);
    return 1;
  }
  vtkDataArray* chosen = this->GetInputArrayToProcess(0, inputVector);
  if (this->IsDistributed(whole))
  {
    return this->RequestDistributedData(input, output, whole, outExt, chosen);
  }
  this->LastRounds = 0;
  if (!std::equal(whole, whole + 6, input->GetExtent()))
  {
    vtkErrorMacro(<< "Occlusion sweeping needs the whole volume; the upstream source delivered "
                     "only part of it.");
    return 1;
  }
  ScalarVolume scalars;
  if (!PrepareScalars(this, chosen, input, this->Component, scalars, error))
  {
    vtkErrorMacro(<< error);
    return 1;
  }

  // Computed on the whole volume; the output is the requested extent.
  vtkNew<vtkImageData> whole3d;
  whole3d->ShallowCopy(input);
  const vao::SweepOutput arrays = AddOutputArrays(whole3d, this->OutputOctantVisibility != 0);
  const double* spacing = input->GetSpacing();
  vao::SweepReport report;
  const vao::Status status =
    vao::computeOcclusionSweeping(scalars.view, { spacing[0], spacing[1], spacing[2] },
      this->Parameters(), arrays, Execution(this, this->NumberOfThreads), &report);
  if (!status.ok)
  {
    error = KernelError(status, scalars, "Occlusion sweeping failed");
    if (!error.empty())
    {
      vtkErrorMacro(<< error);
    }
    return 1;
  }
  if (!report.surfaceFound)
  {
    this->WarnNoSurface(scalars.name);
  }
  this->LastPasses = report.passes;
  this->LastChange = report.lastChange;

  vtkAmbientOcclusionExtents::CopyRequestedExtent(whole3d, output, outExt);
  return 1;
}

//------------------------------------------------------------------------------
std::string vtkOcclusionSweeping::StartSlab(
  vtkImageData* input, vtkDataArray* chosen, const int whole[6], Slab& slab)
{
  const int rank = this->Controller->GetLocalProcessId(),
            ranks = this->Controller->GetNumberOfProcesses();
  int expected[6];
  SlabExtent(whole, rank, ranks, slab.extent);
  SlabInputExtent(whole, rank, ranks, expected);
  const int* inExt = input->GetExtent();
  std::string error;
  if (!std::equal(expected, expected + 6, inExt))
  {
    std::ostringstream why;
    why << "Occlusion sweeping under MPI needs its slab and one ghost layer (" << expected[0]
        << ".." << expected[1] << ", " << expected[2] << ".." << expected[3] << ", " << expected[4]
        << ".." << expected[5] << "); the upstream source delivered (" << inExt[0] << ".."
        << inExt[1] << ", " << inExt[2] << ".." << inExt[3] << ", " << inExt[4] << ".." << inExt[5]
        << ").";
    return why.str();
  }
  if (!PrepareScalars(this, chosen, input, this->Component, slab.scalars, error))
  {
    return error;
  }
  const double* spacing = input->GetSpacing();
  vao::SweepParameters parameters = this->Parameters();
  parameters.tolerance = ExchangeTolerance(this->ConvergenceTolerance, spacing);
  vao::BlockPlacement placement;
  for (int a = 0; a < 3; ++a)
  {
    placement.whole[a] = whole[2 * a + 1] - whole[2 * a] + 1;
    placement.begin[a] = slab.extent[2 * a] - whole[2 * a];
    placement.size[a] = slab.extent[2 * a + 1] - slab.extent[2 * a] + 1;
  }
  slab.block.reset(new vao::BlockSweeper(slab.scalars.view, placement,
    { spacing[0], spacing[1], spacing[2] }, parameters, Execution(this, this->NumberOfThreads)));
  return KernelError(slab.block->initialise(), slab.scalars, "Occlusion sweeping failed");
}

//------------------------------------------------------------------------------
void vtkOcclusionSweeping::ReportStop(const std::string& error)
{
  vtkErrorMacro(<< (error.empty()
                    ? std::string(
                        "Occlusion sweeping stopped: another process failed (see its message).")
                    : error));
}

//------------------------------------------------------------------------------
int vtkOcclusionSweeping::SweepRounds(Slab& slab, int axis, double tolerance)
{
  vao::BlockSweeper& block = *slab.block;
  // Sweep the slab with the ghosts as they are, exchange the faces, until the ghosts
  // settle everywhere (or the process aborts, everywhere).
  vtkMultiProcessController* controller = this->Controller;
  const int ranks = controller->GetNumberOfProcesses();
  const int passesPerRound = std::max(this->NumberOfIterations, 64);
  const int maxRounds = 4 * ranks + 32;
  int rounds = 0;
  double change = 0.0;
  do
  {
    vao::SweepReport report;
    const vao::Status status = block.runRound(passesPerRound, &report);
    // All stop together: 1 an abort (not an error), 2 a failure (no memory) somewhere.
    const double stopped = GlobalMax(controller, status.ok ? 0.0 : status.aborted ? 1.0 : 2.0);
    if (stopped > 0.0)
    {
      if (stopped > 1.0)
        this->ReportStop(KernelError(status, slab.scalars, "Occlusion sweeping failed"));
      return -1;
    }
    change = GlobalMax(controller, ExchangeFaces(controller, block, axis));
    this->LastPasses = report.passes;
    this->LastChange = change;
    this->UpdateProgress(std::min(0.9, 0.9 * (rounds + 1) / (ranks + 2.0)));
  } while (++rounds < maxRounds && change > tolerance);
  if (change > tolerance)
  {
    vtkWarningMacro(<< "Occlusion sweeping: the slabs still changed by " << change << " after "
                    << rounds << " rounds of exchanges.");
  }
  return rounds;
}

//------------------------------------------------------------------------------
int vtkOcclusionSweeping::RequestDistributedData(vtkImageData* input, vtkImageData* output,
  const int whole[6], const int outExt[6], vtkDataArray* chosen)
{
  vtkMultiProcessController* controller = this->Controller;
  // The slab and its ghost layer, from the processes that hold it where the source did not
  // deliver it (a reader that does not split reads everything on one process).
  int expected[6];
  SlabInputExtent(
    whole, controller->GetLocalProcessId(), controller->GetNumberOfProcesses(), expected);
  vtkNew<vtkImageData> fetched, cropped;
  std::string fetchError;
  input = vtkAmbientOcclusionCollectives::CoverNeededExtent(
    controller, input, whole, expected, fetched, fetchError);
  if (!input)
  {
    vtkErrorMacro(<< fetchError); // the same on every process
    return 1;
  }
  if (!std::equal(expected, expected + 6, input->GetExtent()))
  {
    vtkAmbientOcclusionExtents::CopyRequestedExtent(input, cropped, expected);
    input = cropped;
  }
  chosen = this->GetInputArrayToProcess(0, input);
  // Every process checks its slab, then all agree: one that stopped alone would leave
  // the others waiting at the first exchange.
  Slab slab;
  const std::string error = this->StartSlab(input, chosen, whole, slab);
  if (GlobalMax(controller, error.empty() ? 0.0 : 1.0) > 0.0)
  {
    this->ReportStop(error);
    return 1;
  }
  int rounds = 0;
  vao::BlockSweeper& block = *slab.block;
  if (GlobalMax(controller, block.surfaceFound() ? 1.0 : 0.0) == 0.0)
  {
    block.fillWithoutSurface();
    this->WarnNoSurface(slab.scalars.name);
  }
  else
  {
    const double tolerance = ExchangeTolerance(this->ConvergenceTolerance, input->GetSpacing());
    rounds = this->SweepRounds(slab, SlabAxis(whole), tolerance);
    if (rounds < 0)
    {
      return 1;
    }
  }
  this->LastRounds = rounds;

  // The slab's results with the input's arrays, then to whatever extent was requested.
  vtkNew<vtkImageData> held;
  vtkAmbientOcclusionExtents::CopyRequestedExtent(input, held, slab.extent);
  const vao::Status finished =
    block.finish(AddOutputArrays(held, this->OutputOctantVisibility != 0));
  if (GlobalMax(controller, finished.ok ? 0.0 : 1.0) > 0.0) // before the collective below
  {
    this->ReportStop(KernelError(finished, slab.scalars, "Occlusion sweeping failed"));
    return 1;
  }
  vtkNew<vtkIntArray> roundsArray;
  roundsArray->SetName("SweepingExchangeRounds");
  roundsArray->InsertNextValue(rounds);
  held->GetFieldData()->AddArray(roundsArray);
  // The slabs tile the whole extent: every requested voxel is held.
  vtkAmbientOcclusionCollectives::RedistributeExtents(controller, held, outExt, output);
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
void vtkOcclusionSweeping::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "IsoValue: " << this->IsoValue << " (inside is "
     << (this->InsideIsAbove ? "above" : "below") << ")\n";
  os << indent << "NumberOfIterations: " << this->NumberOfIterations
     << ", ConvergenceTolerance: " << this->ConvergenceTolerance << "\n";
  os << indent << "UseGeometryTerm: " << this->UseGeometryTerm << "\n";
  os << indent << "OctantMask:";
  for (int s = 0; s < 8; ++s)
  {
    os << " " << this->OctantMask[s];
  }
  os << "\n" << indent << "Gamma: " << this->Gamma << ", Opacity: " << this->Opacity << "\n";
  os << indent << "OutputOctantVisibility: " << this->OutputOctantVisibility << "\n";
  os << indent << "Component: " << this->Component << ", NumberOfThreads: " << this->NumberOfThreads
     << "\n";
  os << indent << "Controller: " << this->Controller.Get() << "\n";
}
