#include "vtkIsosurfaceAmbientOcclusion.h"

#include "vtkAmbientOcclusionInput.h"

#include "vao/VarianceOcclusionMap.h"

#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
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

/// The pyramid of the last volume, and what it was built from.
struct vtkIsosurfaceAmbientOcclusion::Cache
{
  std::vector<vao::MomentLevel> levels;
  vtkImageData* volume = nullptr;
  vtkMTimeType volumeTime = 0;
  vtkDataArray* array = nullptr;
  vtkMTimeType arrayTime = 0;
  int component = -1;
  int numberOfLevels = 0;
  bool halfResolution = false;
  // The input scalars as the kernels read them (for the half-voxel-inside query).
  vtkAmbientOcclusionInput::ScalarVolume scalars;
  std::array<double, 3> origin{};
  std::array<double, 3> spacing{};
};

//------------------------------------------------------------------------------
vtkIsosurfaceAmbientOcclusion::vtkIsosurfaceAmbientOcclusion()
  : Pyramid(new Cache)
{
  this->SetNumberOfInputPorts(2);
  this->SetInputArrayToProcess(
    0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

vtkIsosurfaceAmbientOcclusion::~vtkIsosurfaceAmbientOcclusion() = default;

//------------------------------------------------------------------------------
void vtkIsosurfaceAmbientOcclusion::SetVolumeScalars(const char* name)
{
  if (name && *name)
  {
    this->SetInputArrayToProcess(0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, name);
  }
  else
  {
    this->SetInputArrayToProcess(0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
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
  // Each piece of the surface samples the pyramid anywhere along its normals and light
  // rays: every process reads the whole volume (the pyramid is not distributed).
  vtkAmbientOcclusionInput::RequestWholeExtent(inputVector[1]->GetInformationObject(0));
  return 1;
}

//------------------------------------------------------------------------------
bool vtkIsosurfaceAmbientOcclusion::CheckParameters()
{
  std::ostringstream why;
  if (this->QueryMode != HALF_VOXEL_INSIDE && this->QueryMode != ISO_VALUE)
    why << "Unknown QueryMode " << this->QueryMode << " (0 Half Voxel Inside, 1 Iso Value).";
  else if (this->QueryMode == ISO_VALUE && !std::isfinite(this->IsoValue))
    why << "IsoValue must be a finite number.";
  else if (this->NumberOfLevels < 1 || this->NumberOfLevels > 16)
    why << "NumberOfLevels must be between 1 and 16 (got " << this->NumberOfLevels << ").";
  else if (!std::isfinite(this->OffsetFactor) || this->OffsetFactor < 0.0)
    why << "OffsetFactor must be a finite, non-negative number (got " << this->OffsetFactor << ").";
  else if (this->Combine != COMBINE_MAX && this->Combine != COMBINE_MEAN)
    why << "Unknown Combine " << this->Combine << " (0 Max, 1 Mean).";
  else if (this->Estimator != CHEBYSHEV && this->Estimator != GAUSSIAN_CDF)
    why << "Unknown Estimator " << this->Estimator << " (0 Chebyshev, 1 Gaussian CDF).";
  else if (this->ComputeShadows)
  {
    const double* l = this->LightDirection;
    const double length = std::sqrt(l[0] * l[0] + l[1] * l[1] + l[2] * l[2]);
    if (!std::isfinite(length) || length == 0.0)
      why << "LightDirection must be a finite, non-zero vector (got " << l[0] << ", " << l[1] << ", " << l[2] << ").";
  }
  if (why.str().empty())
  {
    return true;
  }
  vtkErrorMacro(<< why.str());
  return false;
}

//------------------------------------------------------------------------------
bool vtkIsosurfaceAmbientOcclusion::UpdatePyramid(vtkImageData* volume, vtkDataArray* chosen)
{
  Cache& cache = *this->Pyramid;
  const bool fresh = cache.volume == volume && cache.volumeTime == volume->GetMTime() && cache.array == chosen &&
    (!chosen || cache.arrayTime == chosen->GetMTime()) && cache.component == this->Component &&
    cache.numberOfLevels == this->NumberOfLevels && cache.halfResolution == (this->StartAtHalfResolution != 0) &&
    !cache.levels.empty();
  if (fresh)
  {
    return true;
  }
  cache.levels.clear();
  std::string error;
  if (!vtkAmbientOcclusionInput::CheckWholeExtent(volume->GetExtent(), error) ||
    !vtkAmbientOcclusionInput::PrepareScalars(this, chosen, volume, this->Component, cache.scalars, error) ||
    !vtkAmbientOcclusionInput::BuildPyramid(
      this, cache.scalars, volume, this->NumberOfLevels, this->StartAtHalfResolution != 0, cache.levels, error))
  {
    cache.levels.clear();
    if (!error.empty())
    {
      vtkErrorMacro(<< error);
    }
    return false;
  }
  const double* h = volume->GetSpacing();
  cache.origin = vtkAmbientOcclusionInput::ExtentOrigin(volume);
  cache.spacing = { h[0], h[1], h[2] };
  cache.volume = volume;
  cache.volumeTime = volume->GetMTime();
  cache.array = chosen;
  cache.arrayTime = chosen ? chosen->GetMTime() : 0;
  cache.component = this->Component;
  cache.numberOfLevels = this->NumberOfLevels;
  cache.halfResolution = this->StartAtHalfResolution != 0;
  ++this->PyramidBuilds;
  return true;
}

//------------------------------------------------------------------------------
bool vtkIsosurfaceAmbientOcclusion::SurfaceNormals(vtkPolyData* surface, std::vector<double>& normals)
{
  const vtkIdType n = surface->GetNumberOfPoints();
  normals.resize(static_cast<size_t>(3 * n));
  vtkDataArray* given = surface->GetPointData()->GetNormals();
  if (!given)
  {
    given = surface->GetPointData()->GetArray("Normals");
  }
  if (given && given->GetNumberOfComponents() == 3)
  {
    for (vtkIdType i = 0; i < n; ++i)
    {
      given->GetTuple(i, &normals[3 * i]);
    }
    return true;
  }
  // No normals: the volume gradient at each point, pointing towards lower values.
  const Cache& cache = *this->Pyramid;
  for (vtkIdType i = 0; i < n; ++i)
  {
    double p[3];
    surface->GetPoint(i, p);
    double g[3];
    for (int a = 0; a < 3; ++a)
    {
      std::array<double, 3> forward = { p[0], p[1], p[2] }, backward = forward;
      forward[a] += cache.spacing[a];
      backward[a] -= cache.spacing[a];
      g[a] = (vao::sampleVolume(cache.scalars.view, cache.origin, cache.spacing, forward) -
               vao::sampleVolume(cache.scalars.view, cache.origin, cache.spacing, backward)) /
        (2.0 * cache.spacing[a]);
    }
    const double length = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    if (!(length > 0.0))
    {
      vtkErrorMacro(<< "The surface has no point normals and the volume's gradient is zero at point " << i
                    << ": add normals (e.g. Contour with Compute Normals, or Generate Surface Normals).");
      return false;
    }
    for (int a = 0; a < 3; ++a)
    {
      normals[3 * i + a] = -g[a] / length;
    }
  }
  return true;
}

//------------------------------------------------------------------------------
int vtkIsosurfaceAmbientOcclusion::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
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
  inputVector[1]->GetInformationObject(0)->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  if (!std::equal(whole, whole + 6, volume->GetExtent()))
  {
    // Happens when the surface is extracted from the same source output in pieces (MPI):
    // the shared output then holds the surface's piece, not the whole volume.
    vtkErrorMacro(<< "The volume arrived as a piece, not whole: under MPI, feed the Volume input from its own "
                     "reader rather than from the output the surface was extracted from.");
    return 1;
  }
  if (!this->CheckParameters() || !this->UpdatePyramid(volume, this->GetInputArrayToProcess(0, inputVector)))
  {
    return 1;
  }
  const vtkIdType n = surface->GetNumberOfPoints();
  output->ShallowCopy(surface);
  if (n == 0)
  {
    return 1; // an empty surface (or an empty piece of one): nothing to shade
  }
  // Every point must lie in the volume (half a voxel of slack for contours at its border).
  double bounds[6];
  volume->GetBounds(bounds);
  double surfaceBounds[6];
  surface->GetBounds(surfaceBounds);
  const double* h = volume->GetSpacing();
  for (int a = 0; a < 3; ++a)
  {
    if (surfaceBounds[2 * a] < bounds[2 * a] - 0.5 * h[a] || surfaceBounds[2 * a + 1] > bounds[2 * a + 1] + 0.5 * h[a])
    {
      vtkErrorMacro(<< "The surface reaches outside the volume (axis " << a << ": surface " << surfaceBounds[2 * a]
                    << ".." << surfaceBounds[2 * a + 1] << ", volume " << bounds[2 * a] << ".." << bounds[2 * a + 1]
                    << "): give the volume the surface was extracted from.");
      output->Initialize();
      return 1;
    }
  }
  std::vector<double> points(static_cast<size_t>(3 * n)), normals;
  for (vtkIdType i = 0; i < n; ++i)
  {
    surface->GetPoint(i, &points[3 * i]);
  }
  if (!this->SurfaceNormals(surface, normals))
  {
    output->Initialize();
    return 1;
  }

  vao::SurfaceOcclusionParameters parameters;
  parameters.query = static_cast<vao::SurfaceQuery>(this->QueryMode);
  parameters.isoValue = this->IsoValue;
  parameters.offsetFactor = this->OffsetFactor;
  parameters.estimator = static_cast<vao::SurfaceEstimator>(this->Estimator);
  parameters.combination = static_cast<vao::LevelCombination>(this->Combine);
  const Cache& cache = *this->Pyramid;
  const vao::Execution execution = vtkAmbientOcclusionInput::ExecutionOf(this);
  vtkNew<vtkFloatArray> occlusion;
  occlusion->SetName("AmbientOcclusion");
  occlusion->SetNumberOfTuples(n);
  vao::Status status = vao::surfaceAmbientOcclusion(cache.levels, cache.scalars.view, cache.origin, cache.spacing,
    points.data(), normals.data(), n, parameters, occlusion->GetPointer(0), execution);
  vtkNew<vtkFloatArray> shadow;
  if (status.ok && this->ComputeShadows)
  {
    shadow->SetName("Shadow");
    shadow->SetNumberOfTuples(n);
    const double* l = this->LightDirection;
    status = vao::surfaceShadow(cache.levels, points.data(), normals.data(), n, { l[0], l[1], l[2] }, parameters,
      shadow->GetPointer(0), execution);
  }
  if (!status.ok)
  {
    if (!status.aborted)
    {
      vtkErrorMacro(<< "Isosurface ambient occlusion failed: " << status.message << ".");
    }
    output->Initialize();
    return 1;
  }
  output->GetPointData()->AddArray(occlusion);
  if (this->ComputeShadows)
  {
    output->GetPointData()->AddArray(shadow);
  }
  return 1;
}

//------------------------------------------------------------------------------
void vtkIsosurfaceAmbientOcclusion::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "QueryMode: " << (this->QueryMode == ISO_VALUE ? "Iso Value" : "Half Voxel Inside")
     << ", IsoValue: " << this->IsoValue << "\n";
  os << indent << "NumberOfLevels: " << this->NumberOfLevels << ", StartAtHalfResolution: "
     << this->StartAtHalfResolution << "\n";
  os << indent << "OffsetFactor: " << this->OffsetFactor << "\n";
  os << indent << "Combine: " << (this->Combine == COMBINE_MEAN ? "Mean" : "Max") << ", Estimator: "
     << (this->Estimator == GAUSSIAN_CDF ? "Gaussian CDF" : "Chebyshev") << "\n";
  os << indent << "ComputeShadows: " << this->ComputeShadows << ", LightDirection: " << this->LightDirection[0]
     << " " << this->LightDirection[1] << " " << this->LightDirection[2] << "\n";
  os << indent << "Component: " << this->Component << ", PyramidBuilds: " << this->PyramidBuilds << "\n";
}
