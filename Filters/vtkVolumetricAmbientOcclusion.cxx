// vtkVolumetricAmbientOcclusion: the pipeline's requests, what it refuses before computing
// (and why), Histogram CDF's thresholds, the opacity function it reads, and the run on
// the CPU or the device.
#include "vtkVolumetricAmbientOcclusion.h"

#include "vtkAmbientOcclusionArrayInput.h"
#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionComposite.h"
#include "vtkAmbientOcclusionExtents.h"
#include "vtkAmbientOcclusionMemory.h"
#include "vtkAmbientOcclusionOpacity.h"
#include "vtkAmbientOcclusionRanges.h"
#include "vtkAmbientOcclusionRequest.h"
#include "vtkAmbientOcclusionThresholds.h"

#include "vao/AmbientOcclusion.h"
#include "vao/Cuda.h"
#include "vao/HistogramCdf.h"
#include "vao/Validation.h"

#include "vtkAlgorithmOutput.h"
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
#include <new>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkVolumetricAmbientOcclusion);
vtkCxxSetSmartPointerMacro(vtkVolumetricAmbientOcclusion, Controller, vtkMultiProcessController);
vtkCxxSetSmartPointerMacro(vtkVolumetricAmbientOcclusion, OpacityFunction, vtkPiecewiseFunction);
vtkCxxSetSmartPointerMacro(vtkVolumetricAmbientOcclusion, HistogramThresholds, vtkDataArray);

namespace
{

const char* const MethodNames[] = { "CDF Reconstruction", "Gaussian CDF", "Chebyshev", "Exact Box",
  "Exact Sphere", "Histogram CDF", "Transfer Function", "Exact Rays", "Rays" };
const char* const QueryModeNames[] = { "Voxel Value", "Iso Value", "Smoothed Voxel Value" };

// The filter's Method is the kernel's method, by value.
static_assert(vtkVolumetricAmbientOcclusion::CDF_RECONSTRUCTION ==
    static_cast<int>(vao::Method::CdfReconstruction) &&
  vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF == static_cast<int>(vao::Method::GaussianCdf) &&
  vtkVolumetricAmbientOcclusion::CHEBYSHEV == static_cast<int>(vao::Method::Chebyshev) &&
  vtkVolumetricAmbientOcclusion::EXACT_BOX == static_cast<int>(vao::Method::ExactBox) &&
  vtkVolumetricAmbientOcclusion::EXACT_SPHERE == static_cast<int>(vao::Method::ExactSphere) &&
  vtkVolumetricAmbientOcclusion::HISTOGRAM_CDF == static_cast<int>(vao::Method::HistogramCdf) &&
  vtkVolumetricAmbientOcclusion::TRANSFER_FUNCTION ==
    static_cast<int>(vao::Method::TransferFunction) &&
  vtkVolumetricAmbientOcclusion::EXACT_RAYS == static_cast<int>(vao::Method::ExactRays) &&
  vtkVolumetricAmbientOcclusion::RAYS == static_cast<int>(vao::Method::Rays));

/// The kernel's method; Gaussian CDF for a value out of range, which CheckParameters
/// refuses before any result.
vao::Method KernelMethod(int method)
{
  return method >= vtkVolumetricAmbientOcclusion::CDF_RECONSTRUCTION &&
      method <= vtkVolumetricAmbientOcclusion::RAYS
    ? static_cast<vao::Method>(method)
    : vao::Method::GaussianCdf;
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
  vao::OutputRange range;  // kept by the pass, so that the range cache need not scan
  bool collective = false; // the processes compute one data set together (NeededInput)
  vao::MomentBasis basis;  // then the whole data set's, for the moment sums
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
vtkMultiProcessController* vtkVolumetricAmbientOcclusion::GetController() const
{
  return this->Controller;
}

//------------------------------------------------------------------------------
vtkPiecewiseFunction* vtkVolumetricAmbientOcclusion::GetOpacityFunction() const
{
  return this->OpacityFunction;
}

//------------------------------------------------------------------------------
vtkMTimeType vtkVolumetricAmbientOcclusion::GetMTime()
{
  // An edited function (a point moved, a midpoint changed) re-executes the filter; the
  // other methods do not read it.
  const vtkMTimeType own = this->Superclass::GetMTime();
  return this->UsesOpacityFunction() && this->OpacityFunction
    ? std::max(own, this->OpacityFunction->GetMTime())
    : own;
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::UsesOpacityFunction() const
{
  return this->Method == TRANSFER_FUNCTION || this->CastsRays();
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::CastsRays() const
{
  return this->Method == EXACT_RAYS || this->Method == RAYS;
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
vtkTypeBool vtkVolumetricAmbientOcclusion::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // The output is like the input: an image, or a composite data set of images.
  if (request->Has(vtkDemandDrivenPipeline::REQUEST_DATA_OBJECT()))
    return vtkAmbientOcclusionComposite::RequestDataObject(
      inputVector, outputVector, "vtkImageData");
  return this->Superclass::ProcessRequest(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------
int vtkVolumetricAmbientOcclusion::FillInputPortInformation(int, vtkInformation* info)
{
  vtkAmbientOcclusionComposite::AcceptImagesAndComposites(info);
  return 1;
}

//------------------------------------------------------------------------------
int vtkVolumetricAmbientOcclusion::FillOutputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkDataObject"); // made by ProcessRequest
  return 1;
}

//------------------------------------------------------------------------------
int vtkVolumetricAmbientOcclusion::RequestInformation(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (vtkAmbientOcclusionComposite::IsComposite(inputVector[0]->GetInformationObject(0)))
    return 1; // each volume's pieces are where the composite data set has them
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
  if (vtkAmbientOcclusionComposite::IsComposite(inInfo))
    return 1; // the piece request passes on as it is
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  if (!vtkAmbientOcclusionExtents::CanProduceSubExtent(inInfo))
  {
    // A reader that does not split: all of it on one process, fetched from there by the
    // others (NeededInput).
    const bool shared = vtkAmbientOcclusionRequest::Distributed(this->Controller);
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
  if (vtkAmbientOcclusionComposite::IsComposite(inputVector[0]->GetInformationObject(0)))
    return vtkAmbientOcclusionComposite::ProduceEachVolume(this, this->Controller, inputVector,
      outputVector,
      [&](vtkInformationVector** in, vtkInformationVector* out)
      { return this->RequestData(nullptr, in, out); });
  return vtkAmbientOcclusionRequest::ProduceOutput(this, outputVector,
    "compute it in pieces (streaming or more MPI ranks), on a smaller extent, or without "
    "ComputeVariance.",
    [&] { return this->ProduceOutput(inputVector, outputVector); });
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
  // Collective like the thresholds: every piece's moment sums taken as the whole volume's.
  if (run.collective &&
    (vao::isSeparableMethod(KernelMethod(this->Method)) || this->ComputeVariance))
    run.basis = vtkAmbientOcclusionCollectives::WholeMomentBasis(this->Controller,
      ok ? &run.scalars.view : nullptr, input->GetExtent(), run.outExt, run.whole);
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
  vtkInformationVector** inputVector, vtkInformationVector* outputVector, Run& run,
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
  run.collective = true;
  vtkImageData* covered = vtkAmbientOcclusionCollectives::CoverNeededExtent(
    this->Controller, input, run.whole, needed, fetched, error);
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
  run.parameters.momentBasis = run.basis;
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
  vao::Execution execution = vtkAmbientOcclusionRequest::Execution(this, this->NumberOfThreads);
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
bool vtkVolumetricAmbientOcclusion::CheckParameters()
{
  // The VTK side: enums, names, the radius before it becomes voxels. The kernel's own
  // checks (finiteness) keep its wording, with the property's name.
  std::ostringstream why;
  const std::string opacity = this->UsesOpacityFunction() && this->OpacityFunction
    ? vtkAmbientOcclusionOpacity::Check(this->OpacityFunction, "OpacityFunction")
    : std::string();
  const vao::Status iso = this->QueryMode == ISO_VALUE
    ? vao::checkFiniteParameter(this->IsoValue, "IsoValue")
    : vao::Status::success();
  if (!std::isfinite(this->Radius) || this->Radius < 0.0)
    why << "Radius must be a finite, non-negative number (got " << this->Radius << ").";
  else if (this->Method < CDF_RECONSTRUCTION || this->Method > RAYS)
    why << "Unknown Method " << this->Method
        << " (0 CDF Reconstruction, 1 Gaussian CDF, 2 Chebyshev, 3 Exact Box, 4 Exact Sphere, 5 "
           "Histogram CDF, 6 Transfer Function, 7 Exact Rays, 8 Rays).";
  else if (this->UsesOpacityFunction() && !this->OpacityFunction)
    why << "Method "
        << (this->Method == EXACT_RAYS ? "Exact Rays"
               : this->Method == RAYS  ? "Rays"
                                       : "Transfer Function")
        << " needs an opacity function (OpacityFunction): in ParaView "
           "the opacity transfer function of an array (GetOpacityTransferFunction), in VTK a "
           "vtkPiecewiseFunction.";
  else if (!opacity.empty())
    why << opacity;
  else if (this->Method == EXACT_RAYS &&
    (this->RayCount < 1 || this->RayCount > vao::kMaximumRayCount))
    why << "RayCount must lie in [1, " << vao::kMaximumRayCount << "] (got " << this->RayCount
        << ").";
  else if (this->CastsRays() &&
    !(std::isfinite(this->OpacityUnitDistance) && this->OpacityUnitDistance >= 0.0))
    why << "OpacityUnitDistance must be finite and positive, or 0 for the smallest spacing (got "
        << this->OpacityUnitDistance << ").";
  else if (this->Method == HISTOGRAM_CDF && !vao::checkHistogramBins(this->NumberOfBins).empty())
    why << vao::checkHistogramBins(this->NumberOfBins) << ".";
  else if (this->RadiusUnits != VOXELS && this->RadiusUnits != WORLD)
    why << "Unknown RadiusUnits " << this->RadiusUnits << " (0 Voxels, 1 World).";
  else if (this->QueryMode < VOXEL_VALUE || this->QueryMode > SMOOTHED_VALUE)
    why << "Unknown QueryMode " << this->QueryMode
        << " (0 Voxel Value, 1 Iso Value, 2 Smoothed Voxel Value).";
  else if (this->QueryMode == SMOOTHED_VALUE &&
    !vao::checkQuerySmoothing(this->QuerySmoothing).empty())
    why << vao::checkQuerySmoothing(this->QuerySmoothing) << ".";
  else if (!iso.ok)
    why << iso.message << ".";
  else if (this->ErfApproximation != ERF_EXACT && this->ErfApproximation != ERF_WINITZKI)
    why << "Unknown ErfApproximation " << this->ErfApproximation << " (0 Exact, 1 Winitzki).";
  else if (this->Backend < BACKEND_AUTO || this->Backend > BACKEND_CUDA)
    why << "Unknown Backend " << this->Backend << " (0 Auto, 1 CPU, 2 CUDA).";
  else if (this->Device < -1)
    why << "Device must be -1 (each MPI rank takes its node-local rank modulo the devices) or a "
           "device index, got "
        << this->Device << ".";
  else if (this->NumberOfThreads < 0)
    why << vtkAmbientOcclusionRequest::ThreadsError(this->NumberOfThreads);
  else if (this->OutputArrayName.empty())
    why << "OutputArrayName must not be empty.";
  else if (this->ComputeVariance && this->OutputArrayName == "Variance")
    why << "OutputArrayName 'Variance' is the name of the variance output (ComputeVariance), which "
           "would replace "
           "it: choose another name.";
  if (why.tellp() == 0)
  {
    return true;
  }
  vtkErrorMacro(<< why.str());
  return false;
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::CheckInputCovers(vtkImageData* input, const int outExt[6])
{
  const int* inExt = input->GetExtent();
  for (int a = 0; a < 3; ++a)
  {
    if (outExt[2 * a] < inExt[2 * a] || outExt[2 * a + 1] > inExt[2 * a + 1] ||
      outExt[2 * a] > outExt[2 * a + 1])
    {
      vtkErrorMacro(
        << "The input extent (" << inExt[0] << ".." << inExt[1] << ", " << inExt[2] << ".."
        << inExt[3] << ", " << inExt[4] << ".." << inExt[5]
        << ") does not cover the requested extent: the upstream source ignored the request.");
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::CheckVoxelRadius(
  vtkImageData* input, const int whole[6], int radius[3])
{
  const int wholeDims[3] = { whole[1] - whole[0] + 1, whole[3] - whole[2] + 1,
    whole[5] - whole[4] + 1 };
  const double* h = input->GetSpacing();
  if ((this->RadiusUnits == WORLD || this->CastsRays()) &&
    !(std::isfinite(h[0]) && h[0] > 0.0 && std::isfinite(h[1]) && h[1] > 0.0 &&
      std::isfinite(h[2]) && h[2] > 0.0))
  {
    vtkErrorMacro(<< (this->CastsRays() ? "Rays run in world space: they need"
                                        : "A radius in world units needs")
                  << " a finite, positive spacing on every axis; the input's is " << h[0] << ", "
                  << h[1] << ", " << h[2] << ". Fix the spacing (e.g. with Change Spacing)"
                  << (this->CastsRays() ? "." : " or give the radius in voxels."));
    return false;
  }
  this->ComputeVoxelRadius(h, radius);
  if (this->CastsRays())
  {
    // A ray may run beyond the volume (open sky there): any positive radius is a result.
    const vao::Status rays = vao::checkRayParameters(this->Rays(h));
    if (!rays.ok)
      vtkErrorMacro(<< (this->Method == RAYS ? "Rays: " : "Exact Rays: ") << rays.message << ".");
    return rays.ok;
  }
  if (radius[0] == 0 && radius[1] == 0 && radius[2] == 0)
  {
    vtkErrorMacro(
      << "Radius " << this->Radius << (this->RadiusUnits == WORLD ? " (world units)" : "")
      << " rounds to 0 voxels on every axis: the neighbourhood would be the voxel alone "
         "and the ambient occlusion 1 everywhere. Use at least one voxel.");
    return false;
  }
  if (radius[0] >= wholeDims[0] - 1 && radius[1] >= wholeDims[1] - 1 &&
    radius[2] >= wholeDims[2] - 1)
  {
    vtkErrorMacro(<< "Radius " << this->Radius << " (" << radius[0] << " x " << radius[1] << " x "
                  << radius[2] << " voxels) covers the whole " << wholeDims[0] << " x "
                  << wholeDims[1] << " x " << wholeDims[2]
                  << " volume from every voxel: every neighbourhood "
                  << "would be the whole volume. Use a smaller radius.");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::IsDistributed() const
{
  return this->Method == HISTOGRAM_CDF && !this->HistogramThresholds &&
    vtkAmbientOcclusionRequest::Distributed(this->Controller);
}

//------------------------------------------------------------------------------
vtkDataArray* vtkVolumetricAmbientOcclusion::GetHistogramThresholds() const
{
  return this->HistogramThresholds;
}

//------------------------------------------------------------------------------
vtkSmartPointer<vtkDoubleArray> vtkVolumetricAmbientOcclusion::ComputeHistogramThresholds(int slabs)
{
  vtkAlgorithm* producer =
    this->GetNumberOfInputConnections(0) > 0 ? this->GetInputAlgorithm(0, 0) : nullptr;
  std::string error = vao::checkHistogramBins(this->NumberOfBins);
  std::vector<double> thresholds;
  if (!producer && error.empty())
    error = "no input connection";
  if (error.empty())
  {
    const int port = this->GetInputConnection(0, 0)->GetIndex();
    vtkAmbientOcclusionArrayInput::ScalarVolume scalars; // the slab being read
    bool read = false;
    try // outside RequestData, so outside the filters' memory guard
    {
      read = vtkAmbientOcclusionThresholds::ComputeInSlabs(
        producer, port, slabs, this->NumberOfBins,
        [&](vtkImageData* image, vao::VolumeView& view, std::string& why)
        {
          if (!vtkAmbientOcclusionArrayInput::PrepareScalars(
                this, this->GetInputArrayToProcess(0, image), image, this->Component, scalars, why))
            return false;
          view = scalars.view;
          return true;
        },
        thresholds, error);
    }
    catch (const std::bad_alloc&)
    {
      error = "not enough memory for the value histogram; read the input in more slabs";
    }
    if (!read && error.empty())
      error = "the input could not be read in slabs";
  }
  if (!error.empty())
  {
    vtkErrorMacro(<< "ComputeHistogramThresholds: " << error);
    return nullptr;
  }
  auto array = vtkSmartPointer<vtkDoubleArray>::New();
  array->SetName("HistogramThresholds");
  for (const double t : thresholds)
    array->InsertNextValue(t);
  return array;
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::Thresholds(vtkImageData* input, const vao::VolumeView* volume,
  const vao::ValueScan& scan, const int outExt[6], const int whole[6], bool failed,
  std::vector<double>& thresholds)
{
  std::string error;
  if (this->HistogramThresholds)
  {
    for (vtkIdType i = 0; i < this->HistogramThresholds->GetNumberOfTuples(); ++i)
      thresholds.push_back(this->HistogramThresholds->GetComponent(i, 0));
    const vao::Status status = vao::checkHistogramThresholds(thresholds);
    if (!status.ok)
      error = "HistogramThresholds: " + status.message + ".";
  }
  else
  {
    // Distributed: each process counts its output piece (together they tile the data
    // set); one process counts its input, which is the whole extent.
    const bool distributed = this->IsDistributed();
    // One process counts the whole array: its thresholds are kept on it for the next run.
    vtkDataArray* counted =
      !distributed && volume ? this->GetInputArrayToProcess(0, input) : nullptr;
    if (counted &&
      vtkAmbientOcclusionThresholds::Recall(
        counted, this->Component, this->NumberOfBins, thresholds))
      return !failed;
    vtkAmbientOcclusionThresholds::Piece piece;
    piece.volume = volume;
    piece.scan = &scan;
    piece.inExt = volume ? input->GetExtent() : outExt;
    piece.outExt = distributed || !volume ? outExt : input->GetExtent();
    piece.whole = whole;
    piece.failed = failed;
    const bool computed = vtkAmbientOcclusionThresholds::Compute(
      distributed ? this->Controller.Get() : nullptr, piece, this->NumberOfBins, thresholds, error);
    if (!computed && error.empty())
      return false; // aborted, or this process failed and said why before
    if (computed)
      vtkAmbientOcclusionThresholds::Remember(
        counted, this->Component, this->NumberOfBins, thresholds);
  }
  if (!error.empty())
  {
    vtkErrorMacro(<< error);
  }
  return error.empty() && !failed;
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
