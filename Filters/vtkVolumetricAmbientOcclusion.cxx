#include "vtkVolumetricAmbientOcclusion.h"

#include "vtkAmbientOcclusionMemory.h"

#include "vtkAmbientOcclusionArrayInput.h"
#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionExtents.h"
#include "vtkAmbientOcclusionOpacity.h"
#include "vtkAmbientOcclusionRanges.h"
#include "vtkAmbientOcclusionThresholds.h"

#include "vao/AmbientOcclusion.h"
#include "vao/Cuda.h"
#include "vao/Validation.h"

#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkFieldData.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkIntArray.h"
#include "vtkMatrix3x3.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <vector>

vtkStandardNewMacro(vtkVolumetricAmbientOcclusion);

namespace
{

const char* const MethodNames[] = { "CDF Reconstruction", "Gaussian CDF", "Chebyshev", "Exact Box",
  "Exact Sphere", "Histogram CDF", "Transfer Function", "Exact Rays", "Rays" };
const char* const QueryModeNames[] = { "Voxel Value", "Iso Value", "Smoothed Voxel Value" };

vao::Method KernelMethod(int method)
{
  switch (method)
  {
    case vtkVolumetricAmbientOcclusion::CDF_RECONSTRUCTION:
      return vao::Method::CdfReconstruction;
    case vtkVolumetricAmbientOcclusion::CHEBYSHEV:
      return vao::Method::Chebyshev;
    case vtkVolumetricAmbientOcclusion::EXACT_BOX:
      return vao::Method::ExactBox;
    case vtkVolumetricAmbientOcclusion::EXACT_SPHERE:
      return vao::Method::ExactSphere;
    case vtkVolumetricAmbientOcclusion::HISTOGRAM_CDF:
      return vao::Method::HistogramCdf;
    case vtkVolumetricAmbientOcclusion::TRANSFER_FUNCTION:
      return vao::Method::TransferFunction;
    case vtkVolumetricAmbientOcclusion::EXACT_RAYS:
      return vao::Method::ExactRays;
    case vtkVolumetricAmbientOcclusion::RAYS:
      return vao::Method::Rays;
    case vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF:
    default: // CheckParameters rejects any other value
      return vao::Method::GaussianCdf;
  }
}

vao::QueryMode KernelQueryMode(int mode)
{
  switch (mode)
  {
    case vtkVolumetricAmbientOcclusion::ISO_VALUE:
      return vao::QueryMode::IsoValue;
    case vtkVolumetricAmbientOcclusion::SMOOTHED_VALUE:
      return vao::QueryMode::SmoothedValue;
    default:
      return vao::QueryMode::VoxelValue;
  }
}

vao::ErfMode KernelErfMode(int erf)
{
  return erf == vtkVolumetricAmbientOcclusion::ERF_WINITZKI ? vao::ErfMode::Winitzki
                                                            : vao::ErfMode::Exact;
}

vtkSmartPointer<vtkFloatArray> NewFloatArray(const char* name, vtkIdType values)
{
  auto array = vtkSmartPointer<vtkFloatArray>::New();
  array->SetName(name);
  vtkAmbientOcclusionMemory::Allocate(array, values, std::string("the ") + name + " output");
  return array;
}

} // namespace

/// One RequestData's state, filled by its steps in turn.
struct vtkVolumetricAmbientOcclusion::Run
{
  int whole[6] = {};       // the data set's whole extent
  int outExt[6] = {};      // the extent to produce
  int radius[3] = {};      // the box's half-widths in voxels
  bool emptyPiece = false; // this process's piece of a distributed data set has no voxel
  vtkAmbientOcclusionArrayInput::ScalarVolume scalars;
  vao::ValueScan scan; // Histogram CDF without given thresholds: the values' range
  std::vector<double> thresholds;
  vao::AmbientOcclusionParameters parameters; // the kernel's, the thresholds moved in
  vtkSmartPointer<vtkFloatArray> openness;
  vtkSmartPointer<vtkFloatArray> variance;
  vao::OutputRange range; // kept by the pass, so that the range cache need not scan
};

//------------------------------------------------------------------------------
vtkVolumetricAmbientOcclusion::vtkVolumetricAmbientOcclusion()
  : Controller(vtkMultiProcessController::GetGlobalController())
{
  this->SetInputArrayToProcess(
    0, 0, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

//------------------------------------------------------------------------------
void vtkVolumetricAmbientOcclusion::ComputeVoxelRadius(const double spacing[3], int radius[3]) const
{
  if (this->CastsRays())
  {
    const std::array<int, 3> reach = this->Method == RAYS
      ? vao::rayEstimateReach(this->Rays(spacing))
      : vao::rayReach(this->Rays(spacing));
    std::copy(reach.begin(), reach.end(), radius);
    return;
  }
  for (int a = 0; a < 3; ++a)
  {
    double voxels = this->Radius;
    if (this->RadiusUnits == WORLD)
    {
      voxels = spacing[a] > 0.0 ? this->Radius / spacing[a] : 0.0;
    }
    // Bounded so an absurd radius cannot overflow; CheckParameters reports it.
    voxels = std::isfinite(voxels) ? std::min(std::max(voxels, 0.0), 1e9) : 0.0;
    // Half-integers round up, and so do ratios a rounding error below one (5.5 x 1.3 mm over
    // 1.3 mm is 5.5, the same in metres 5.499999999999999): the same radius and spacing in
    // other units give the same voxels.
    radius[a] = static_cast<int>(std::floor(voxels + 0.5 + 1e-12 * voxels));
  }
}

//------------------------------------------------------------------------------
void vtkVolumetricAmbientOcclusion::SetController(vtkMultiProcessController* controller)
{
  if (this->Controller != controller)
  {
    this->Controller = controller;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
vtkMultiProcessController* vtkVolumetricAmbientOcclusion::GetController() const
{
  return this->Controller;
}

//------------------------------------------------------------------------------
void vtkVolumetricAmbientOcclusion::ComputeReach(const double spacing[3], int reach[3]) const
{
  this->ComputeVoxelRadius(spacing, reach);
  if (this->QueryMode == SMOOTHED_VALUE && !this->UsesOpacityFunction())
  {
    const int window = vao::querySmoothingHalfWidth(this->QuerySmoothing);
    for (int a = 0; a < 3; ++a)
      reach[a] = std::max(reach[a], window);
  }
}

//------------------------------------------------------------------------------
vao::AmbientOcclusionParameters vtkVolumetricAmbientOcclusion::Parameters(const int radius[3]) const
{
  vao::AmbientOcclusionParameters parameters;
  parameters.method = KernelMethod(this->Method);
  parameters.radius = { radius[0], radius[1], radius[2] };
  parameters.queryMode = KernelQueryMode(this->QueryMode);
  parameters.isoValue = this->IsoValue;
  parameters.erfMode = KernelErfMode(this->ErfApproximation);
  parameters.querySmoothing = this->QuerySmoothing;
  if (this->UsesOpacityFunction())
  {
    parameters.queryMode = vao::QueryMode::VoxelValue; // the opacity has no query
    parameters.opacity = vtkAmbientOcclusionOpacity::Nodes(this->OpacityFunction);
  }
  return parameters;
}

//------------------------------------------------------------------------------
vao::RayParameters vtkVolumetricAmbientOcclusion::Rays(const double spacing[3]) const
{
  vao::RayParameters rays;
  rays.spacing = { spacing[0], spacing[1], spacing[2] };
  const double smallest = std::min({ spacing[0], spacing[1], spacing[2] });
  rays.radius = this->RadiusUnits == WORLD ? this->Radius : this->Radius * smallest;
  rays.opacityUnitDistance = this->OpacityUnitDistance;
  if (this->Method == EXACT_RAYS)
    rays.rayCount = this->RayCount; // Rays casts none: its cones are fixed
  return rays;
}

//------------------------------------------------------------------------------
int vtkVolumetricAmbientOcclusion::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  // Any sub-extent can be computed (from that extent grown by the radius), so the
  // executive may turn a piece request (MPI rank, streaming) into an extent request here.
  outputVector->GetInformationObject(0)->Set(CAN_PRODUCE_SUB_EXTENT(), 1);
  return 1;
}

//------------------------------------------------------------------------------
int vtkVolumetricAmbientOcclusion::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  if (!vtkAmbientOcclusionExtents::CanProduceSubExtent(inInfo))
  {
    // A reader that does not split: all of it on one process, fetched from there by the
    // others (NeededInput).
    const bool shared = this->Controller && this->Controller->GetNumberOfProcesses() > 1;
    vtkAmbientOcclusionExtents::RequestPieceOfWhole(inInfo,
      shared ? this->Controller->GetLocalProcessId() : 0,
      shared ? this->Controller->GetNumberOfProcesses() : 1);
    return 1;
  }
  if (this->Method == HISTOGRAM_CDF && !this->HistogramThresholds && !this->IsDistributed())
  {
    // One process: the thresholds need every voxel of the data set.
    vtkAmbientOcclusionExtents::RequestWholeExtent(inInfo);
    return 1;
  }
  int ext[6], whole[6], radius[3];
  outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), ext);
  inInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  double spacing[3] = { 1.0, 1.0, 1.0 };
  if (inInfo->Has(vtkDataObject::SPACING()))
  {
    inInfo->Get(vtkDataObject::SPACING(), spacing);
  }
  this->ComputeReach(spacing, radius);
  // Every neighbourhood of the requested extent, clipped to the whole extent, must arrive.
  // An extent request is grown here; a piece request (MPI ranks, streaming by pieces) is
  // turned into an extent by the source's executive, which grows it by the ghost levels:
  // ask for as many more as the largest radius, as vtkImageGradient asks for one.
  if (!vtkAmbientOcclusionExtents::EmptyExtent(ext))
  {
    vtkAmbientOcclusionExtents::GrowExtent(ext, radius, whole);
  }
  inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), ext, 6);
  const int ghostLevels =
    outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS());
  inInfo->Set(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_GHOST_LEVELS(),
    ghostLevels + std::max({ radius[0], radius[1], radius[2] }));
  return 1;
}

//------------------------------------------------------------------------------
int vtkVolumetricAmbientOcclusion::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkDataObject* output = vtkDataObject::GetData(outputVector, 0);
  // Allocation failure anywhere below (caching the ranges too) is an error and an empty
  // output, not an abort.
  return vtkAmbientOcclusionMemory::Guard(this, output,
    "compute it in pieces (streaming or more MPI ranks), on a smaller extent, or without "
    "ComputeVariance.",
    [&]() -> int
    {
      const int result = this->ProduceOutput(inputVector, outputVector);
      vtkAmbientOcclusionRanges::CacheOutput(output);
      return result;
    });
}

//------------------------------------------------------------------------------
int vtkVolumetricAmbientOcclusion::ProduceOutput(
  vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkImageData* input = vtkImageData::GetData(inputVector[0]);
  vtkImageData* output = vtkImageData::GetData(outputVector);
  output->Initialize();
  this->LastBackend.clear();
  this->LastDevice.clear();
  if (!this->CheckParameters()) // the same on every process
  {
    return 1;
  }
  Run run;
  std::string error;
  if (input &&
    !vtkAmbientOcclusionExtents::WholeAndRequestedExtent(
      inputVector[0], outputVector, run.whole, run.outExt, error))
  {
    vtkErrorMacro(<< error);
    return 1; // the whole extent is the same on every process
  }
  vtkNew<vtkImageData> fetched;
  input = this->NeededInput(input, inputVector, outputVector, run, fetched);
  if (!input)
  {
    return 1; // the same on every process
  }
  const bool ok = this->ReadInput(input, run);
  // Collective in a distributed run: every process takes part, also one that failed above
  // (it says so, and every process then stops) or holds an empty piece.
  if (this->Method == HISTOGRAM_CDF && (ok || this->IsDistributed()) &&
    !this->Thresholds(input, ok ? &run.scalars.view : nullptr, run.scan, run.outExt, run.whole,
      !ok && !run.emptyPiece, run.thresholds))
  {
    return 1;
  }
  if (ok && this->ComputeArrays(input, run))
  {
    this->AssembleOutput(input, output, run);
  }
  return 1;
}

//------------------------------------------------------------------------------
vtkImageData* vtkVolumetricAmbientOcclusion::NeededInput(vtkImageData* input,
  vtkInformationVector** inputVector, vtkInformationVector* outputVector, const Run& run,
  vtkImageData* fetched)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkInformation* inInfo = inputVector[0]->GetInformationObject(0);
  // Ranks that each run their own pipeline (one piece of a splitting source) share
  // nothing: no collective.
  if (!input || !this->Controller || this->Controller->GetNumberOfProcesses() < 2 ||
    (outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES()) < 2 &&
      vtkAmbientOcclusionExtents::CanProduceSubExtent(inInfo)))
  {
    return input;
  }
  // The pipeline's spacing: an empty piece's image has none of its own.
  double spacing[3] = { 1.0, 1.0, 1.0 };
  if (inInfo->Has(vtkDataObject::SPACING()))
  {
    inInfo->Get(vtkDataObject::SPACING(), spacing);
  }
  int reach[3], needed[6];
  this->ComputeReach(spacing, reach);
  std::copy(run.outExt, run.outExt + 6, needed);
  if (!vtkAmbientOcclusionExtents::EmptyExtent(needed))
  {
    vtkAmbientOcclusionExtents::GrowExtent(needed, reach, run.whole);
  }
  std::string error;
  vtkImageData* covered = vtkAmbientOcclusionCollectives::CoverNeededExtent(
    this->Controller, input, needed, fetched, error);
  if (!covered)
  {
    vtkErrorMacro(<< error);
  }
  return covered;
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::ReadInput(vtkImageData* input, Run& run)
{
  // An empty piece of a distributed data set (e.g. MetaImage on rank > 0) has nothing
  // to compute, but still takes part in the thresholds of Histogram CDF.
  run.emptyPiece = input && input->GetNumberOfPoints() == 0;
  if (!input || run.emptyPiece || !this->CheckInputCovers(input, run.outExt) ||
    !this->CheckVoxelRadius(input, run.whole, run.radius))
  {
    return false;
  }
  std::string error;
  if (!vtkAmbientOcclusionArrayInput::PrepareScalars(
        this, this->GetInputArrayToProcess(0, input), input, this->Component, run.scalars, error))
  {
    vtkErrorMacro(<< error);
    return false;
  }
  if (this->Method == HISTOGRAM_CDF && !this->HistogramThresholds)
  {
    // One pass for the thresholds' value range and, before them (they count finite
    // values only), the kernel's own message for NaN and infinite voxels.
    run.scan = vao::scanValues(run.scalars.view);
    const vao::Status finite = vao::finiteStatus(run.scan);
    if (!finite.ok)
    {
      vtkErrorMacro(<< vtkAmbientOcclusionArrayInput::KernelError(
                      finite, run.scalars, "Ambient occlusion failed"));
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::ComputeArrays(vtkImageData* input, Run& run)
{
  vao::Region region;
  for (int a = 0; a < 3; ++a)
  {
    region.begin[a] = run.outExt[2 * a] - input->GetExtent()[2 * a];
    region.size[a] = run.outExt[2 * a + 1] - run.outExt[2 * a] + 1;
  }
  run.openness = NewFloatArray(this->OutputArrayName.c_str(), region.voxelCount());
  run.variance = this->ComputeVariance ? NewFloatArray("Variance", region.voxelCount()) : nullptr;
  run.parameters = this->Parameters(run.radius);
  run.parameters.thresholds = std::move(run.thresholds);
  if (this->CastsRays())
  {
    run.parameters.rays = this->Rays(input->GetSpacing());
    const double* d = input->GetDirectionMatrix()->GetData();
    std::copy(d, d + 9, run.parameters.rays.direction.begin());
  }
  const vao::Status status = this->Compute(run.scalars.view, region, run.parameters,
    { run.openness->GetPointer(0), run.variance ? run.variance->GetPointer(0) : nullptr,
      &run.range });
  if (!status.ok)
  {
    const std::string error =
      vtkAmbientOcclusionArrayInput::KernelError(status, run.scalars, "Ambient occlusion failed");
    if (!error.empty())
    {
      vtkErrorMacro(<< error);
    }
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumetricAmbientOcclusion::AssembleOutput(
  vtkImageData* input, vtkImageData* output, const Run& run)
{
  // The output is exactly the requested extent: the input's arrays cropped to it.
  vtkAmbientOcclusionExtents::CopyRequestedExtent(input, output, run.outExt);
  output->GetPointData()->AddArray(run.openness);
  if (run.range.known)
    vtkAmbientOcclusionRanges::CacheKnown(run.openness, run.range.lowest, run.range.highest);
  if (run.variance)
  {
    output->GetPointData()->AddArray(run.variance);
  }
  this->RecordRun(output, run.parameters.thresholds);
}

//------------------------------------------------------------------------------
void vtkVolumetricAmbientOcclusion::RecordRun(
  vtkImageData* output, const std::vector<double>& thresholds)
{
  if (this->Method == HISTOGRAM_CDF)
  {
    vtkNew<vtkDoubleArray> used; // for a later run to reuse, e.g. on other pieces
    used->SetName("HistogramThresholds");
    for (const double t : thresholds)
      used->InsertNextValue(t);
    output->GetFieldData()->AddArray(used);
  }
  vtkNew<vtkStringArray> backend;
  backend->SetName("AmbientOcclusionBackend");
  backend->InsertNextValue(this->LastBackend);
  output->GetFieldData()->AddArray(backend);
  vtkNew<vtkStringArray> device;
  device->SetName("AmbientOcclusionDevice");
  device->InsertNextValue(this->LastDevice);
  output->GetFieldData()->AddArray(device);
  // The CPU threads this process used (or would have used, on the GPU backend): under
  // MPI the cores are shared among the node's ranks.
  vtkNew<vtkIntArray> threads;
  threads->SetName("AmbientOcclusionThreads");
  threads->InsertNextValue(vao::threadCount(this->NumberOfThreads));
  output->GetFieldData()->AddArray(threads);
}

//------------------------------------------------------------------------------
vao::Status vtkVolumetricAmbientOcclusion::Compute(const vao::VolumeView& volume,
  const vao::Region& region, const vao::AmbientOcclusionParameters& parameters,
  const vao::AmbientOcclusionOutput& arrays)
{
  vao::Execution execution =
    vtkAmbientOcclusionArrayInput::ExecutionOf(this, this->NumberOfThreads);
  execution.device = this->Device;
  vao::Status status;
  // The device runs every method but Transfer Function, with the voxel's value or an iso
  // value as the query.
  const char* cpuOnly = parameters.method == vao::Method::TransferFunction
    ? "The Transfer Function method runs"
    : parameters.method == vao::Method::ExactRays           ? "The Exact Rays method runs"
    : parameters.method == vao::Method::Rays                ? "The Rays method runs"
    : parameters.queryMode == vao::QueryMode::SmoothedValue ? "The smoothed query runs"
                                                            : nullptr;
  bool onDevice = this->ChooseCuda(cpuOnly,
    !vao::isSeparableMethod(parameters.method) && parameters.method != vao::Method::HistogramCdf,
    region.voxelCount());
  if (onDevice)
  {
    status = vao::cuda::computeAmbientOcclusion(volume, region, parameters, arrays, execution);
    // Bad input fails on the CPU too, with the same message: only a device failure
    // falls back.
    if (!status.ok && status.deviceFailure)
    {
      vtkWarningMacro(<< "The CUDA backend failed (" << status.message
                      << "); computing on the CPU.");
      onDevice = false;
    }
  }
  if (!onDevice)
  {
    status = vao::computeAmbientOcclusion(volume, region, parameters, arrays, execution);
  }
  this->LastBackend = onDevice ? "CUDA" : "CPU";
  this->LastDevice = onDevice ? "CUDA " + vao::cuda::deviceStatus(this->Device).description : "CPU";
  return status;
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::ChooseCuda(
  const char* cpuOnly, bool exactMethod, long long voxels)
{
  if (this->Backend == BACKEND_CPU)
  {
    return false;
  }
  const vao::cuda::DeviceStatus device = vao::cuda::deviceStatus(this->Device);
  if (this->Backend == BACKEND_AUTO)
  {
    // Below about a million voxels the CPU finishes before the transfers would, except
    // for the exact references, whose O(R^3) counts pay for them at any size.
    return device.available && !cpuOnly && (exactMethod || voxels >= AutoCudaMinimumVoxels);
  }
  if (cpuOnly)
  {
    vtkWarningMacro(<< cpuOnly << " on the CPU only; computing on the CPU.");
    return false;
  }
  if (!device.available)
  {
    vtkWarningMacro(<< "Backend CUDA: no CUDA device (" << device.description
                    << "); computing on the CPU.");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumetricAmbientOcclusion::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  const bool knownMethod = this->Method >= CDF_RECONSTRUCTION && this->Method <= RAYS;
  const bool knownQuery = this->QueryMode >= VOXEL_VALUE && this->QueryMode <= SMOOTHED_VALUE;
  os << indent << "Method: " << (knownMethod ? MethodNames[this->Method] : "(invalid)") << "\n";
  os << indent << "NumberOfBins: " << this->NumberOfBins << "\n";
  os << indent << "RayCount: " << this->RayCount << "\n";
  os << indent << "OpacityUnitDistance: " << this->OpacityUnitDistance << "\n";
  os << indent << "Radius: " << this->Radius << (this->RadiusUnits == WORLD ? " world" : " voxels")
     << "\n";
  os << indent << "QueryMode: " << (knownQuery ? QueryModeNames[this->QueryMode] : "(invalid)")
     << "\n";
  os << indent << "IsoValue: " << this->IsoValue << "\n";
  os << indent << "QuerySmoothing: " << this->QuerySmoothing << "\n";
  os << indent << "Controller: " << this->Controller.Get() << "\n";
  os << indent
     << "ErfApproximation: " << (this->ErfApproximation == ERF_WINITZKI ? "Winitzki" : "Exact")
     << "\n";
  os << indent << "ComputeVariance: " << this->ComputeVariance << "\n";
  os << indent << "Component: " << this->Component << "\n";
  os << indent << "Backend: " << this->Backend << " (last run: " << this->LastBackend << ")\n";
  os << indent << "Device: " << this->Device << " (last run: " << this->LastDevice << ")\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "OutputArrayName: " << this->OutputArrayName << "\n";
}
