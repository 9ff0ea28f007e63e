#include "vtkVolumetricAmbientOcclusion.h"

#include "vtkAmbientOcclusionMemory.h"

#include "vtkAmbientOcclusionArrayInput.h"
#include "vtkAmbientOcclusionExtents.h"
#include "vtkAmbientOcclusionRanges.h"
#include "vtkAmbientOcclusionThresholds.h"

#include "vao/AmbientOcclusion.h"
#include "vao/Cuda.h"
#include "vao/HistogramCdf.h"
#include "vao/Validation.h"

#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
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
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"
#include "vtkStringArray.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkVolumetricAmbientOcclusion);

namespace
{

const char* const MethodNames[] = { "CDF Reconstruction", "Gaussian CDF", "Chebyshev", "Exact Box",
  "Exact Sphere", "Histogram CDF" };
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
  return erf == vtkVolumetricAmbientOcclusion::ERF_WINITZKI ? vao::ErfMode::Winitzki : vao::ErfMode::Exact;
}

vtkSmartPointer<vtkFloatArray> NewFloatArray(const char* name, vtkIdType values)
{
  auto array = vtkSmartPointer<vtkFloatArray>::New();
  array->SetName(name);
  vtkAmbientOcclusionMemory::Allocate(array, values, std::string("the ") + name + " output");
  return array;
}

} // namespace

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
  if (this->QueryMode == SMOOTHED_VALUE)
  {
    const int window = vao::querySmoothingHalfWidth(this->QuerySmoothing);
    for (int a = 0; a < 3; ++a)
      reach[a] = std::max(reach[a], window);
  }
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::CheckParameters()
{
  // The VTK side: enums, names, the radius before it becomes voxels. The kernel's own
  // checks (finiteness) keep its wording, with the property's name.
  std::ostringstream why;
  const vao::Status iso = this->QueryMode == ISO_VALUE ? vao::checkFiniteParameter(this->IsoValue, "IsoValue")
                                                       : vao::Status::success();
  if (!std::isfinite(this->Radius) || this->Radius < 0.0)
    why << "Radius must be a finite, non-negative number (got " << this->Radius << ").";
  else if (this->Method < CDF_RECONSTRUCTION || this->Method > HISTOGRAM_CDF)
    why << "Unknown Method " << this->Method
        << " (0 CDF Reconstruction, 1 Gaussian CDF, 2 Chebyshev, 3 Exact Box, 4 Exact Sphere, 5 Histogram CDF).";
  else if (this->Method == HISTOGRAM_CDF && !vao::checkHistogramBins(this->NumberOfBins).empty())
    why << vao::checkHistogramBins(this->NumberOfBins) << ".";
  else if (this->RadiusUnits != VOXELS && this->RadiusUnits != WORLD)
    why << "Unknown RadiusUnits " << this->RadiusUnits << " (0 Voxels, 1 World).";
  else if (this->QueryMode < VOXEL_VALUE || this->QueryMode > SMOOTHED_VALUE)
    why << "Unknown QueryMode " << this->QueryMode << " (0 Voxel Value, 1 Iso Value, 2 Smoothed Voxel Value).";
  else if (this->QueryMode == SMOOTHED_VALUE && !vao::checkQuerySmoothing(this->QuerySmoothing).empty())
    why << vao::checkQuerySmoothing(this->QuerySmoothing) << ".";
  else if (!iso.ok)
    why << iso.message << ".";
  else if (this->ErfApproximation != ERF_EXACT && this->ErfApproximation != ERF_WINITZKI)
    why << "Unknown ErfApproximation " << this->ErfApproximation << " (0 Exact, 1 Winitzki).";
  else if (this->Backend < BACKEND_AUTO || this->Backend > BACKEND_CUDA)
    why << "Unknown Backend " << this->Backend << " (0 Auto, 1 CPU, 2 CUDA).";
  else if (this->Device < -1)
    why << "Device must be -1 (each MPI rank takes its node-local rank modulo the devices) or a device index, got "
        << this->Device << ".";
  else if (this->NumberOfThreads < 0)
    why << vtkAmbientOcclusionArrayInput::NumberOfThreadsError(this->NumberOfThreads);
  else if (this->OutputArrayName.empty())
    why << "OutputArrayName must not be empty.";
  else if (this->ComputeVariance && this->OutputArrayName == "Variance")
    why << "OutputArrayName 'Variance' is the name of the variance output (ComputeVariance), which would replace "
           "it: choose another name.";
  if (why.tellp() == 0)
  {
    return true;
  }
  vtkErrorMacro(<< why.str());
  return false;
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
  return parameters;
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
bool vtkVolumetricAmbientOcclusion::CheckInputCovers(vtkImageData* input, const int outExt[6])
{
  const int* inExt = input->GetExtent();
  for (int a = 0; a < 3; ++a)
  {
    if (outExt[2 * a] < inExt[2 * a] || outExt[2 * a + 1] > inExt[2 * a + 1] || outExt[2 * a] > outExt[2 * a + 1])
    {
      vtkErrorMacro(<< "The input extent (" << inExt[0] << ".." << inExt[1] << ", " << inExt[2] << ".."
                    << inExt[3] << ", " << inExt[4] << ".." << inExt[5]
                    << ") does not cover the requested extent: the upstream source ignored the request.");
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::CheckVoxelRadius(vtkImageData* input, const int whole[6], int radius[3])
{
  const int wholeDims[3] = { whole[1] - whole[0] + 1, whole[3] - whole[2] + 1, whole[5] - whole[4] + 1 };
  const double* h = input->GetSpacing();
  if (this->RadiusUnits == WORLD &&
    !(std::isfinite(h[0]) && h[0] > 0.0 && std::isfinite(h[1]) && h[1] > 0.0 && std::isfinite(h[2]) && h[2] > 0.0))
  {
    vtkErrorMacro(<< "A radius in world units needs a finite, positive spacing on every axis; the input's is "
                  << h[0] << ", " << h[1] << ", " << h[2]
                  << ". Fix the spacing (e.g. with Change Spacing) or give the radius in voxels.");
    return false;
  }
  this->ComputeVoxelRadius(h, radius);
  if (radius[0] == 0 && radius[1] == 0 && radius[2] == 0)
  {
    vtkErrorMacro(<< "Radius " << this->Radius << (this->RadiusUnits == WORLD ? " (world units)" : "")
                  << " rounds to 0 voxels on every axis: the neighbourhood would be the voxel alone "
                     "and the ambient occlusion 1 everywhere. Use at least one voxel.");
    return false;
  }
  if (radius[0] >= wholeDims[0] - 1 && radius[1] >= wholeDims[1] - 1 && radius[2] >= wholeDims[2] - 1)
  {
    vtkErrorMacro(<< "Radius " << this->Radius << " (" << radius[0] << " x " << radius[1] << " x "
                  << radius[2] << " voxels) covers the whole " << wholeDims[0] << " x " << wholeDims[1]
                  << " x " << wholeDims[2] << " volume from every voxel: every neighbourhood "
                  << "would be the whole volume. Use a smaller radius.");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
int vtkVolumetricAmbientOcclusion::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // Allocation failure anywhere below is an error and an empty output, not an abort.
  return vtkAmbientOcclusionMemory::Guard(this, vtkDataObject::GetData(outputVector, 0),
    "compute it in pieces (streaming or more MPI ranks), on a smaller extent, or without ComputeVariance.", [&]() -> int {
    vtkImageData* input = vtkImageData::GetData(inputVector[0]);
    vtkImageData* output = vtkImageData::GetData(outputVector);
    output->Initialize();
    this->LastBackend.clear();
    this->LastDevice.clear();
    if (!this->CheckParameters()) // the same on every process
    {
      return 1;
    }
    int whole[6], outExt[6], radius[3];
    std::string error;
    bool ok = input != nullptr;
    if (ok && !vtkAmbientOcclusionExtents::WholeAndRequestedExtent(inputVector[0], outputVector, whole, outExt, error))
    {
      vtkErrorMacro(<< error);
      return 1; // the whole extent is the same on every process
    }
    // An empty piece of a distributed data set (e.g. MetaImage on rank > 0) has nothing
    // to compute, but still takes part in the thresholds of Histogram CDF.
    const bool emptyPiece = ok && input->GetNumberOfPoints() == 0;
    ok = ok && !emptyPiece && this->CheckInputCovers(input, outExt) && this->CheckVoxelRadius(input, whole, radius);
    vtkAmbientOcclusionArrayInput::ScalarVolume scalars;
    if (ok &&
      !vtkAmbientOcclusionArrayInput::PrepareScalars(
        this, this->GetInputArrayToProcess(0, inputVector), input, this->Component, scalars, error))
    {
      vtkErrorMacro(<< error);
      ok = false;
    }
    vao::ValueScan scan;
    if (ok && this->Method == HISTOGRAM_CDF && !this->HistogramThresholds)
    {
      // One pass for the thresholds' value range and, before them (they count finite
      // values only), the kernel's own message for NaN and infinite voxels.
      scan = vao::scanValues(scalars.view);
      const vao::Status finite = vao::finiteStatus(scan);
      if (!finite.ok)
      {
        vtkErrorMacro(<< vtkAmbientOcclusionArrayInput::KernelError(finite, scalars, "Ambient occlusion failed"));
        ok = false;
      }
    }
    std::vector<double> thresholds;
    if (this->Method == HISTOGRAM_CDF && (ok || this->IsDistributed()) &&
      !this->Thresholds(input, ok ? &scalars.view : nullptr, scan, outExt, whole, !ok && !emptyPiece, thresholds))
    {
      return 1;
    }
    if (!ok)
    {
      return 1;
    }

    vao::Region region;
    for (int a = 0; a < 3; ++a)
    {
      region.begin[a] = outExt[2 * a] - input->GetExtent()[2 * a];
      region.size[a] = outExt[2 * a + 1] - outExt[2 * a] + 1;
    }
    auto openness = NewFloatArray(this->OutputArrayName.c_str(), region.voxelCount());
    auto variance = this->ComputeVariance ? NewFloatArray("Variance", region.voxelCount()) : nullptr;
    vao::AmbientOcclusionParameters parameters = this->Parameters(radius);
    parameters.thresholds = std::move(thresholds);
    vao::OutputRange range; // kept by the pass, so that the range cache need not scan
    const vao::Status status = this->Compute(scalars.view, region, parameters,
      { openness->GetPointer(0), variance ? variance->GetPointer(0) : nullptr, &range });
    if (!status.ok)
    {
      error = vtkAmbientOcclusionArrayInput::KernelError(status, scalars, "Ambient occlusion failed");
      if (!error.empty())
      {
        vtkErrorMacro(<< error);
      }
      return 1;
    }

    // The output is exactly the requested extent: the input's arrays cropped to it.
    vtkAmbientOcclusionExtents::CopyRequestedExtent(input, output, outExt);
    output->GetPointData()->AddArray(openness);
    if (range.known)
      vtkAmbientOcclusionRanges::CacheKnown(openness, range.lowest, range.highest);
    if (variance)
    {
      output->GetPointData()->AddArray(variance);
    }
    if (this->Method == HISTOGRAM_CDF)
    {
      vtkNew<vtkDoubleArray> used; // for a later run to reuse, e.g. on other pieces
      used->SetName("HistogramThresholds");
      for (const double t : parameters.thresholds)
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
    return 1;
  });
}

//------------------------------------------------------------------------------
vao::Status vtkVolumetricAmbientOcclusion::Compute(const vao::VolumeView& volume, const vao::Region& region,
  const vao::AmbientOcclusionParameters& parameters, const vao::AmbientOcclusionOutput& arrays)
{
  vao::Execution execution = vtkAmbientOcclusionArrayInput::ExecutionOf(this, this->NumberOfThreads);
  execution.device = this->Device;
  vao::Status status;
  // The device runs every method, with the voxel's value or an iso value as the query.
  bool onDevice = this->ChooseCuda(parameters.queryMode != vao::QueryMode::SmoothedValue,
    !vao::isSeparableMethod(parameters.method) && parameters.method != vao::Method::HistogramCdf,
    region.voxelCount());
  if (onDevice)
  {
    status = vao::cuda::computeAmbientOcclusion(volume, region, parameters, arrays, execution);
    // Bad input fails on the CPU too, with the same message: only a device failure
    // falls back.
    if (!status.ok && status.deviceFailure)
    {
      vtkWarningMacro(<< "The CUDA backend failed (" << status.message << "); computing on the CPU.");
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
bool vtkVolumetricAmbientOcclusion::ChooseCuda(bool onDeviceQuery, bool exactMethod, long long voxels)
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
    return device.available && onDeviceQuery && (exactMethod || voxels >= AutoCudaMinimumVoxels);
  }
  if (!onDeviceQuery)
  {
    vtkWarningMacro(<< "The smoothed query runs on the CPU only; computing on the CPU.");
    return false;
  }
  if (!device.available)
  {
    vtkWarningMacro(<< "Backend CUDA: no CUDA device (" << device.description << "); computing on the CPU.");
    return false;
  }
  return true;
}

//------------------------------------------------------------------------------
void vtkVolumetricAmbientOcclusion::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  const bool knownMethod = this->Method >= CDF_RECONSTRUCTION && this->Method <= HISTOGRAM_CDF;
  const bool knownQuery = this->QueryMode >= VOXEL_VALUE && this->QueryMode <= SMOOTHED_VALUE;
  os << indent << "Method: " << (knownMethod ? MethodNames[this->Method] : "(invalid)") << "\n";
  os << indent << "NumberOfBins: " << this->NumberOfBins << "\n";
  os << indent << "Radius: " << this->Radius << (this->RadiusUnits == WORLD ? " world" : " voxels") << "\n";
  os << indent << "QueryMode: " << (knownQuery ? QueryModeNames[this->QueryMode] : "(invalid)") << "\n";
  os << indent << "IsoValue: " << this->IsoValue << "\n";
  os << indent << "QuerySmoothing: " << this->QuerySmoothing << "\n";
  os << indent << "Controller: " << this->Controller.Get() << "\n";
  os << indent << "ErfApproximation: " << (this->ErfApproximation == ERF_WINITZKI ? "Winitzki" : "Exact") << "\n";
  os << indent << "ComputeVariance: " << this->ComputeVariance << "\n";
  os << indent << "Component: " << this->Component << "\n";
  os << indent << "Backend: " << this->Backend << " (last run: " << this->LastBackend << ")\n";
  os << indent << "Device: " << this->Device << " (last run: " << this->LastDevice << ")\n";
  os << indent << "NumberOfThreads: " << this->NumberOfThreads << "\n";
  os << indent << "OutputArrayName: " << this->OutputArrayName << "\n";
}
