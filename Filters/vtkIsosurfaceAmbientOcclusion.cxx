#include "vtkIsosurfaceAmbientOcclusion.h"

#include "vtkAmbientOcclusionMemory.h"
#include "vtkAmbientOcclusionRanges.h"

#include "vtkAmbientOcclusionArrayInput.h"
#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionExtents.h"

#include "vao/Validation.h"
#include "vao/VarianceOcclusionMap.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <string>
#include <vector>

vtkStandardNewMacro(vtkIsosurfaceAmbientOcclusion);
vtkCxxSetSmartPointerMacro(vtkIsosurfaceAmbientOcclusion, Controller, vtkMultiProcessController);

namespace Extents = vtkAmbientOcclusionExtents;

namespace
{
/// Voxels a distributed surface piece may reach beyond its volume piece (ghost cells).
constexpr int kSurfaceSlack = 2;
} // namespace

vtkMultiProcessController* vtkIsosurfaceAmbientOcclusion::GetController() const
{
  return this->Controller;
}

//------------------------------------------------------------------------------
void vtkIsosurfaceAmbientOcclusion::SetVolumeScalars(
  int, int, int, int association, const char* name)
{
  if (association != vtkDataObject::FIELD_ASSOCIATION_POINTS)
  {
    vtkErrorMacro(<< "Scalars must be a point array of the volume (got association " << association
                  << ").");
    return;
  }
  this->SetVolumeScalars(name);
}

//------------------------------------------------------------------------------
void vtkIsosurfaceAmbientOcclusion::SetVolumeScalars(const char* name)
{
  if (name && *name)
  {
    this->SetInputArrayToProcess(0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, name);
  }
  else
  {
    this->SetInputArrayToProcess(
      0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
  }
}

//------------------------------------------------------------------------------
int vtkIsosurfaceAmbientOcclusion::FillInputPortInformation(int port, vtkInformation* info)
{
  info->Set(vtkAlgorithm::INPUT_REQUIRED_DATA_TYPE(), port == 0 ? "vtkPolyData" : "vtkImageData");
  return 1;
}

//------------------------------------------------------------------------------
int vtkIsosurfaceAmbientOcclusion::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // One process reads the whole volume. Several read their piece grown by the reach of
  // the finer levels' queries; the coarsest level is shared (UpdateDistributedPyramid).
  vtkInformation* volumeInfo = inputVector[1]->GetInformationObject(0);
  if (!this->IsDistributed())
  {
    Extents::RequestWholeExtent(volumeInfo);
    return 1;
  }
  if (!Extents::CanProduceSubExtent(volumeInfo))
  {
    // A reader that does not split: read on one process, sent whole to the processes
    // with surface points (ProduceOutput).
    Extents::RequestPieceOfWhole(
      volumeInfo, this->Controller->GetLocalProcessId(), this->Controller->GetNumberOfProcesses());
    return 1;
  }
  int whole[6], piece[6], ext[6];
  double spacing[3] = { 1.0, 1.0, 1.0 };
  volumeInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  if (volumeInfo->Has(vtkDataObject::SPACING()))
  {
    volumeInfo->Get(vtkDataObject::SPACING(), spacing);
  }
  this->VolumeExtentOf(whole, spacing, piece, ext);
  Extents::RequestExactExtent(volumeInfo, ext);
  return 1;
}

//------------------------------------------------------------------------------
bool vtkIsosurfaceAmbientOcclusion::CheckParameters()
{
  // The VTK side: enums and the ranges the filter relies on before any kernel runs (the
  // reach of a piece). The kernel's own checks (finiteness) keep its wording.
  std::ostringstream why;
  const double* l = this->LightDirection;
  const vao::Status iso = this->QueryMode == ISO_VALUE
    ? vao::checkFiniteParameter(this->IsoValue, "IsoValue")
    : vao::Status::success();
  const vao::Status light = this->ComputeShadows
    ? vao::checkFinitePoint({ l[0], l[1], l[2] }, "LightDirection")
    : vao::Status::success();
  const double length = std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
  if (this->QueryMode != HALF_VOXEL_INSIDE && this->QueryMode != ISO_VALUE)
    why << "Unknown QueryMode " << this->QueryMode << " (0 Half Voxel Inside, 1 Iso Value).";
  else if (!iso.ok)
    why << iso.message << ".";
  else if (this->NumberOfLevels < 1 || this->NumberOfLevels > 16)
    why << "NumberOfLevels must be between 1 and 16 (got " << this->NumberOfLevels << ").";
  else if (!std::isfinite(this->OffsetFactor) || this->OffsetFactor < 0.0)
    why << "OffsetFactor must be a finite, non-negative number (got " << this->OffsetFactor << ").";
  else if (this->Combine != COMBINE_MAX && this->Combine != COMBINE_MEAN)
    why << "Unknown Combine " << this->Combine << " (0 Max, 1 Mean).";
  else if (this->Estimator != CHEBYSHEV && this->Estimator != GAUSSIAN_CDF)
    why << "Unknown Estimator " << this->Estimator << " (0 Chebyshev, 1 Gaussian CDF).";
  else if (!light.ok)
    why << light.message << ".";
  else if (this->ComputeShadows && !(std::isfinite(length) && length > 0.0))
    why << "LightDirection must be a non-zero vector of finite length (got " << l[0] << ", " << l[1]
        << ", " << l[2] << ").";
  else if (this->NumberOfThreads < 0)
    why << vtkAmbientOcclusionArrayInput::NumberOfThreadsError(this->NumberOfThreads);
  if (why.tellp() == 0)
  {
    return true;
  }
  vtkErrorMacro(<< why.str());
  return false;
}

//------------------------------------------------------------------------------
vao::SurfaceOcclusionParameters vtkIsosurfaceAmbientOcclusion::Parameters() const
{
  vao::SurfaceOcclusionParameters parameters;
  parameters.query =
    this->QueryMode == ISO_VALUE ? vao::SurfaceQuery::IsoValue : vao::SurfaceQuery::HalfVoxelInside;
  parameters.isoValue = this->IsoValue;
  parameters.offsetFactor = this->OffsetFactor;
  parameters.estimator =
    this->Estimator == GAUSSIAN_CDF ? vao::Method::GaussianCdf : vao::Method::Chebyshev;
  parameters.combination = this->Combine == COMBINE_MEAN ? vao::LevelCombination::Mean
                                                         : vao::LevelCombination::MaximumOcclusion;
  return parameters;
}

vao::PyramidParameters vtkIsosurfaceAmbientOcclusion::PyramidRequest() const
{
  return { this->NumberOfLevels, this->StartAtHalfResolution != 0 };
}

//------------------------------------------------------------------------------
bool vtkIsosurfaceAmbientOcclusion::IsDistributed() const
{
  return this->Controller && this->Controller->GetNumberOfProcesses() > 1 &&
    this->NumberOfLevels >= 2;
}

//------------------------------------------------------------------------------
void vtkIsosurfaceAmbientOcclusion::VolumeExtentOf(
  const int whole[6], const double spacing[3], int piece[6], int ext[6]) const
{
  Extents::PieceOfWhole(
    this->Controller->GetLocalProcessId(), this->Controller->GetNumberOfProcesses(), whole, piece);
  if (Extents::EmptyExtent(piece))
  {
    std::copy(piece, piece + 6, ext);
    return;
  }
  const int levels = std::max(2, std::min(this->NumberOfLevels, 16));
  Extents::GrowForSurfaceQueries(whole, piece, spacing, levels, this->StartAtHalfResolution != 0,
    this->OffsetFactor, kSurfaceSlack, ext);
}

//------------------------------------------------------------------------------
bool vtkIsosurfaceAmbientOcclusion::CheckSurfaceInVolume(
  vtkPolyData* surface, vtkImageData* volume, const int whole[6], const int piece[6])
{
  // Every point must lie in the volume (half a voxel of slack for contours at its border),
  // or near this process's piece of it: a surface piece extracted with ghost cells
  // reaches a voxel or two beyond the piece.
  const int slack = this->IsDistributed() ? kSurfaceSlack : 0;
  const int slacks[3] = { slack, slack, slack };
  int reached[6];
  std::copy(piece, piece + 6, reached);
  Extents::GrowExtent(reached, slacks, whole);
  const double* origin = volume->GetOrigin();
  const double* h = volume->GetSpacing();
  double bounds[6], surfaceBounds[6];
  for (int a = 0; a < 6; ++a)
  {
    bounds[a] = origin[a / 2] + reached[a] * h[a / 2];
  }
  this->PlaceSurface(surface, surfaceBounds);
  for (int a = 0; a < 3; ++a)
  {
    if (surfaceBounds[2 * a] < bounds[2 * a] - 0.5 * h[a] ||
      surfaceBounds[2 * a + 1] > bounds[2 * a + 1] + 0.5 * h[a])
    {
      vtkErrorMacro(<< "The surface reaches outside the volume (axis " << a << ": surface "
                    << surfaceBounds[2 * a] << ".." << surfaceBounds[2 * a + 1] << ", volume "
                    << bounds[2 * a] << ".." << bounds[2 * a + 1]
                    << "): give the volume the surface was extracted from.");
      return false;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
int vtkIsosurfaceAmbientOcclusion::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkDataObject* output = vtkDataObject::GetData(outputVector, 0);
  // Allocation failure anywhere below (caching the ranges too) is an error and an empty
  // output, not an abort.
  return vtkAmbientOcclusionMemory::Guard(this, output,
    "try StartAtHalfResolution, fewer NumberOfLevels, or more MPI ranks.",
    [&]() -> int
    {
      const int result = this->ProduceOutput(inputVector, outputVector);
      vtkAmbientOcclusionRanges::CacheOutput(output);
      return result;
    });
}

//------------------------------------------------------------------------------
int vtkIsosurfaceAmbientOcclusion::ProduceOutput(
  vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPolyData* surface = vtkPolyData::GetData(inputVector[0]);
  vtkImageData* volume = vtkImageData::GetData(inputVector[1]);
  vtkPolyData* output = vtkPolyData::GetData(outputVector);
  output->Initialize();
  if (!surface || !volume)
  {
    vtkErrorMacro(<< "Needs a surface (input 0) and a volume (input 1).");
    return 1;
  }
  int whole[6];
  inputVector[1]->GetInformationObject(0)->Get(
    vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  bool distributed = this->IsDistributed();
  vtkNew<vtkImageData> fetched;
  vtkDataArray* chosen = this->GetInputArrayToProcess(0, inputVector);
  if (distributed && !Extents::CanProduceSubExtent(inputVector[1]->GetInformationObject(0)))
  {
    // The volume's reader does not split: every process with surface points takes the
    // whole volume from the one that read it, and shades its points as one process does.
    if (!this->CheckParameters()) // the same answer on every process, before the collective
    {
      return 1;
    }
    const int none[6] = { 0, -1, 0, -1, 0, -1 };
    std::string error;
    volume = vtkAmbientOcclusionCollectives::CoverNeededExtent(
      this->Controller, volume, surface->GetNumberOfPoints() > 0 ? whole : none, fetched, error);
    if (!volume)
    {
      vtkErrorMacro(<< error);
      return 1;
    }
    if (surface->GetNumberOfPoints() == 0)
    {
      output->ShallowCopy(surface);
      return 1;
    }
    chosen = this->GetInputArrayToProcess(0, volume);
    distributed = false;
  }
  if (!distributed && !std::equal(whole, whole + 6, volume->GetExtent()))
  {
    // Happens when the surface is extracted from the same source output in pieces (MPI):
    // the shared output then holds the surface's piece, not the whole volume.
    vtkErrorMacro(
      << "The volume arrived as a piece, not whole: under MPI, feed the Volume input from its own "
         "reader rather than from the output the surface was extracted from.");
    return 1;
  }
  if (!this->CheckParameters()) // the same answer on every process
  {
    return 1;
  }
  int piece[6];
  std::copy(whole, whole + 6, piece);
  if (distributed ? !this->UpdateDistributedPyramid(volume, chosen, whole, piece)
                  : !this->UpdatePyramid(volume, chosen))
  {
    return 1;
  }
  output->ShallowCopy(surface);
  if (surface->GetNumberOfPoints() == 0)
  {
    return 1; // an empty surface (or an empty piece of one): nothing to shade
  }
  if (!this->CheckSurfaceInVolume(surface, volume, whole, piece) || !this->Shade(surface, output))
  {
    output->Initialize();
  }
  return 1;
}

//------------------------------------------------------------------------------
void vtkIsosurfaceAmbientOcclusion::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent
     << "QueryMode: " << (this->QueryMode == ISO_VALUE ? "Iso Value" : "Half Voxel Inside")
     << ", IsoValue: " << this->IsoValue << "\n";
  os << indent << "NumberOfLevels: " << this->NumberOfLevels
     << ", StartAtHalfResolution: " << this->StartAtHalfResolution << "\n";
  os << indent << "OffsetFactor: " << this->OffsetFactor << "\n";
  os << indent << "Combine: " << (this->Combine == COMBINE_MEAN ? "Mean" : "Max")
     << ", Estimator: " << (this->Estimator == GAUSSIAN_CDF ? "Gaussian CDF" : "Chebyshev") << "\n";
  os << indent << "ComputeShadows: " << this->ComputeShadows
     << ", LightDirection: " << this->LightDirection[0] << " " << this->LightDirection[1] << " "
     << this->LightDirection[2] << "\n";
  os << indent << "Component: " << this->Component << ", NumberOfThreads: " << this->NumberOfThreads
     << ", PyramidBuilds: " << this->PyramidBuilds << "\n";
  os << indent << "Controller: " << this->Controller.Get() << "\n";
}
