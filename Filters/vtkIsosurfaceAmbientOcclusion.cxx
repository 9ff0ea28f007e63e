#include "vtkIsosurfaceAmbientOcclusion.h"

#include "vtkAmbientOcclusionInput.h"

#include "vao/VarianceOcclusionMap.h"

#include "vtkDataArray.h"
#include "vtkFloatArray.h"
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

namespace
{
/// Voxels a distributed surface piece may reach beyond its volume piece (ghost cells).
constexpr int kSurfaceSlack = 2;
}

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
  vtkSmartPointer<vtkMultiProcessController> controller;
};

//------------------------------------------------------------------------------
vtkIsosurfaceAmbientOcclusion::vtkIsosurfaceAmbientOcclusion()
  : Pyramid(new Cache)
{
  this->Pyramid->controller = vtkMultiProcessController::GetGlobalController();
  this->SetNumberOfInputPorts(2);
  this->SetInputArrayToProcess(
    0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

vtkIsosurfaceAmbientOcclusion::~vtkIsosurfaceAmbientOcclusion() = default;

void vtkIsosurfaceAmbientOcclusion::SetController(vtkMultiProcessController* controller)
{
  if (this->Pyramid->controller != controller)
  {
    this->Pyramid->controller = controller;
    this->Modified();
  }
}

vtkMultiProcessController* vtkIsosurfaceAmbientOcclusion::GetController() const
{
  return this->Pyramid->controller;
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
  // One process reads the whole volume. Several read their piece grown by the reach of
  // the finer levels' queries; the coarsest level is shared (UpdateDistributedPyramid).
  vtkInformation* volumeInfo = inputVector[1]->GetInformationObject(0);
  if (!this->IsDistributed())
  {
    vtkAmbientOcclusionInput::RequestWholeExtent(volumeInfo);
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
  vtkAmbientOcclusionInput::RequestExactExtent(volumeInfo, ext);
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
bool vtkIsosurfaceAmbientOcclusion::IsDistributed() const
{
  const vtkMultiProcessController* controller = this->Pyramid->controller;
  return controller && const_cast<vtkMultiProcessController*>(controller)->GetNumberOfProcesses() > 1 &&
    this->NumberOfLevels >= 2;
}

//------------------------------------------------------------------------------
void vtkIsosurfaceAmbientOcclusion::VolumeExtentOf(
  const int whole[6], const double spacing[3], int piece[6], int ext[6]) const
{
  vtkMultiProcessController* controller = this->Pyramid->controller;
  vtkAmbientOcclusionInput::PieceOfWhole(
    controller->GetLocalProcessId(), controller->GetNumberOfProcesses(), whole, piece);
  if (vtkAmbientOcclusionInput::EmptyExtent(piece))
  {
    std::copy(piece, piece + 6, ext);
    return;
  }
  // How far from a surface point the finer levels (0 .. L-2) are sampled: AO at
  // k * r_l along the normal, shadows from r_0 out to r_0 * 2^(l+1) (where level l + 1
  // takes over), the gradient and the half-voxel query within a voxel; plus the
  // trilinear reach of the level's grid. Every voxel of those levels there must be right:
  // plus their own reach in the input. The coarsest level must be right over the piece.
  const bool half = this->StartAtHalfResolution != 0;
  const int levels = std::max(2, std::min(this->NumberOfLevels, 16));
  const double largest = std::max({ spacing[0], spacing[1], spacing[2] });
  const double r0 = 2.0 * largest * (half ? 2 : 1);
  double reach = 2.0 * largest;
  for (int l = 0; l + 1 < levels; ++l)
  {
    const double step = static_cast<double>((half ? 2 : 1) << l);
    const double r = r0 * (1 << l);
    reach = std::max(reach, std::max(this->OffsetFactor * r, r0 * (2 << l)) + step * largest);
  }
  int reaches[3];
  for (int a = 0; a < 3; ++a)
  {
    reaches[a] = std::max(vtkAmbientOcclusionInput::PyramidReach(levels, half),
      static_cast<int>(std::ceil(reach / spacing[a])) + 1 + kSurfaceSlack +
        vtkAmbientOcclusionInput::PyramidReach(levels - 1, half));
  }
  vtkAmbientOcclusionInput::GrowForPyramid(
    whole, piece, reaches, vtkAmbientOcclusionInput::PyramidAlignment(levels, half), ext);
}

//------------------------------------------------------------------------------
bool vtkIsosurfaceAmbientOcclusion::UpdateDistributedPyramid(
  vtkImageData* volume, vtkDataArray* chosen, const int whole[6], int piece[6])
{
  Cache& cache = *this->Pyramid;
  vtkMultiProcessController* controller = cache.controller;
  cache.levels.clear();
  cache.volume = nullptr; // not reused: the pieces follow the decomposition
  std::string error;
  int expected[6];
  this->VolumeExtentOf(whole, volume->GetSpacing(), piece, expected);
  const bool empty = vtkAmbientOcclusionInput::EmptyExtent(piece);
  const int levels = this->NumberOfLevels;
  const bool half = this->StartAtHalfResolution != 0;
  const int coarsestStep = (half ? 2 : 1) << (levels - 1);
  int coarseExt[6] = { 0, -1, 0, -1, 0, -1 };
  std::vector<float> mine;
  if (!empty && !std::equal(expected, expected + 6, volume->GetExtent()))
  {
    error = "The volume input delivered another extent than this process's piece and its reach: under MPI, "
            "feed the Volume input from its own reader.";
  }
  else if (!empty &&
    vtkAmbientOcclusionInput::CheckWholeExtent(whole, error) &&
    vtkAmbientOcclusionInput::PrepareScalars(this, chosen, volume, this->Component, cache.scalars, error) &&
    vtkAmbientOcclusionInput::BuildPyramid(this, cache.scalars, volume, levels, half, cache.levels, error))
  {
    // This piece's voxels of the coarsest level, for every process.
    auto part = vtkAmbientOcclusionInput::LevelPiece(cache.levels[levels - 1], whole, expected, piece, coarsestStep);
    if (part->GetNumberOfPoints() > 0)
    {
      part->GetExtent(coarseExt);
      for (const char* name : { "Mean", "Variance" })
      {
        vtkDataArray* values = part->GetPointData()->GetArray(name);
        for (vtkIdType i = 0; i < values->GetNumberOfTuples(); ++i)
          mine.push_back(static_cast<float>(values->GetTuple1(i)));
      }
    }
  }
  const int ranks = controller->GetNumberOfProcesses();
  std::vector<int> extents(static_cast<size_t>(6 * ranks));
  controller->AllGather(coarseExt, extents.data(), 6);
  std::vector<vtkIdType> lengths(ranks), offsets(ranks);
  vtkIdType total = 0;
  for (int r = 0; r < ranks; ++r)
  {
    lengths[r] = 2 * vtkAmbientOcclusionInput::ExtentPoints(&extents[6 * r]); // Mean, then Variance
    offsets[r] = total;
    total += lengths[r];
  }
  std::vector<float> all(static_cast<size_t>(std::max<vtkIdType>(total, 1)));
  controller->AllGatherV(mine.data(), all.data(), static_cast<vtkIdType>(mine.size()), lengths.data(), offsets.data());
  const bool failed = !error.empty() || (!empty && cache.levels.empty());
  const bool anyFailed = vtkAmbientOcclusionInput::GlobalMax(controller, failed ? 1.0 : 0.0) > 0.0;
  if (anyFailed || empty)
  {
    if (anyFailed)
    {
      vtkErrorMacro(<< (error.empty() ? std::string("The pyramid failed on another process (see its message).") : error));
    }
    cache.levels.clear();
    return false;
  }

  // The whole coarsest level, from the pieces (they overlap where pieces share a face).
  vao::MomentLevel coarsest;
  const double* h = volume->GetSpacing();
  const double* origin = volume->GetOrigin();
  for (int a = 0; a < 3; ++a)
  {
    // Each halving keeps voxels 0, 2, 4, ...: a level of step s keeps ceil(n / s).
    coarsest.dims[a] = (whole[2 * a + 1] - whole[2 * a] + coarsestStep) / coarsestStep;
    coarsest.origin[a] = origin[a] + whole[2 * a] * h[a];
    coarsest.spacing[a] = h[a] * coarsestStep;
  }
  coarsest.kernelRadius = cache.levels[levels - 1].kernelRadius;
  const vtkIdType nx = coarsest.dims[0], ny = coarsest.dims[1];
  coarsest.mean.resize(static_cast<size_t>(nx * ny * coarsest.dims[2]));
  coarsest.variance.resize(coarsest.mean.size());
  for (int r = 0; r < ranks; ++r)
  {
    const int* e = &extents[6 * r];
    const float* from = all.data() + offsets[r];
    const vtkIdType count = lengths[r] / 2;
    vtkIdType i = 0;
    for (int k = e[4]; k <= e[5]; ++k)
      for (int j = e[2]; j <= e[3]; ++j)
        for (int x = e[0]; x <= e[1]; ++x, ++i)
        {
          const vtkIdType at = (static_cast<vtkIdType>(k) * ny + j) * nx + x;
          coarsest.mean[at] = from[i];
          coarsest.variance[at] = from[count + i];
        }
  }
  cache.levels[levels - 1] = std::move(coarsest);
  // The shadows' march stops at the whole volume's border, not at this piece's.
  vao::MomentLevel& base = cache.levels[0];
  const int baseStep = half ? 2 : 1;
  for (int a = 0; a < 3; ++a)
  {
    const int n = (whole[2 * a + 1] - whole[2 * a] + baseStep) / baseStep; // ceil(voxels / step)
    base.wholeBounds[2 * a] = origin[a] + whole[2 * a] * h[a];
    base.wholeBounds[2 * a + 1] = base.wholeBounds[2 * a] + (n - 1) * h[a] * baseStep;
  }
  cache.origin = vtkAmbientOcclusionInput::ExtentOrigin(volume);
  cache.spacing = { h[0], h[1], h[2] };
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
  const bool distributed = this->IsDistributed();
  if (!distributed && !std::equal(whole, whole + 6, volume->GetExtent()))
  {
    // Happens when the surface is extracted from the same source output in pieces (MPI):
    // the shared output then holds the surface's piece, not the whole volume.
    vtkErrorMacro(<< "The volume arrived as a piece, not whole: under MPI, feed the Volume input from its own "
                     "reader rather than from the output the surface was extracted from.");
    return 1;
  }
  if (!this->CheckParameters()) // the same answer on every process
  {
    return 1;
  }
  int piece[6];
  std::copy(whole, whole + 6, piece);
  vtkDataArray* chosen = this->GetInputArrayToProcess(0, inputVector);
  if (distributed ? !this->UpdateDistributedPyramid(volume, chosen, whole, piece)
                  : !this->UpdatePyramid(volume, chosen))
  {
    return 1;
  }
  const vtkIdType n = surface->GetNumberOfPoints();
  output->ShallowCopy(surface);
  if (n == 0)
  {
    return 1; // an empty surface (or an empty piece of one): nothing to shade
  }
  // Every point must lie in the volume (half a voxel of slack for contours at its border),
  // or near this process's piece of it: a surface piece extracted with ghost cells
  // reaches a voxel or two beyond the piece.
  double bounds[6];
  const double* origin = volume->GetOrigin();
  for (int a = 0; a < 6; ++a)
  {
    const int slack = distributed ? (a % 2 ? kSurfaceSlack : -kSurfaceSlack) : 0;
    const int index = std::max(whole[a & ~1], std::min(whole[a | 1], piece[a] + slack));
    bounds[a] = origin[a / 2] + index * volume->GetSpacing()[a / 2];
  }
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
  parameters.estimator = this->Estimator == GAUSSIAN_CDF ? vao::Method::GaussianCdf : vao::Method::Chebyshev;
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
