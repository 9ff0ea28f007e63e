// vtkIsosurfaceAmbientOcclusion: the pipeline requests and checks, and what it keeps
// between updates: the moment pyramid (built once per volume, serially or as distributed
// pieces with a shared coarsest level) and the last AmbientOcclusion (which a light move
// reuses), and the shading that samples them.
#include "vtkIsosurfaceAmbientOcclusion.h"

#include "vtkAmbientOcclusionArrayInput.h"
#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionComposite.h"
#include "vtkAmbientOcclusionExtents.h"
#include "vtkAmbientOcclusionFrame.h"
#include "vtkAmbientOcclusionMemory.h"
#include "vtkAmbientOcclusionPyramidImages.h"
#include "vtkAmbientOcclusionRequest.h"

#include "vao/Validation.h"
#include "vao/VarianceOcclusionMap.h"

#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMatrix3x3.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <sstream>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

vtkStandardNewMacro(vtkIsosurfaceAmbientOcclusion);
vtkCxxSetSmartPointerMacro(vtkIsosurfaceAmbientOcclusion, Controller, vtkMultiProcessController);

namespace Extents = vtkAmbientOcclusionExtents;
namespace PyramidImages = vtkAmbientOcclusionPyramidImages;
using vtkAmbientOcclusionArrayInput::PrepareScalars;
using vtkAmbientOcclusionArrayInput::SurfacePoints;
using vtkAmbientOcclusionRequest::Execution;

namespace
{
/// Voxels a distributed surface piece may reach beyond its volume piece (ghost cells).
constexpr int kSurfaceSlack = 2;

/// The part of the progress bar the pyramid's build takes; the surface's queries take
/// the rest (a skipped build, from the cache, jumps over it).
constexpr double kPyramidShare = 0.5;

/// What a surface's AmbientOcclusion depends on besides the pyramid (its build count): the
/// point and normal arrays (by identity and MTime, as for the volume), the point count and
/// the query.
struct SurfaceKey
{
  vtkDataArray* points = nullptr;
  vtkMTimeType pointsTime = 0;
  vtkDataArray* normals = nullptr;
  vtkMTimeType normalsTime = 0;
  vtkIdType count = 0;
  std::array<double, 6> query{};
  int pyramidBuilds = 0;

  SurfaceKey() = default;
  SurfaceKey(vtkPolyData* surface, const vao::SurfaceOcclusionParameters& p, int builds)
    : points(surface->GetPoints() ? surface->GetPoints()->GetData() : nullptr)
    , normals(vtkAmbientOcclusionArrayInput::GivenNormals(surface))
    , count(surface->GetNumberOfPoints())
    , query{ static_cast<double>(p.query), p.isoValue, p.offsetFactor,
      static_cast<double>(p.estimator), static_cast<double>(p.combination),
      static_cast<double>(p.levels) }
    , pyramidBuilds(builds)
  {
    this->pointsTime = this->points ? this->points->GetMTime() : 0;
    this->normalsTime = this->normals ? this->normals->GetMTime() : 0;
  }

  bool operator==(const SurfaceKey& o) const
  {
    return std::tie(this->points, this->pointsTime, this->normals, this->normalsTime, this->count,
             this->query, this->pyramidBuilds) ==
      std::tie(o.points, o.pointsTime, o.normals, o.normalsTime, o.count, o.query, o.pyramidBuilds);
  }
};

/// What the shading's kernels read besides the pyramid and the points.
struct Sampling
{
  const vao::VolumeView& volume;
  const std::array<double, 3>& origin;
  const std::array<double, 3>& spacing;
  const vao::SurfaceOcclusionParameters parameters;
  const vao::Execution execution;
};

/// The shading's kernels on the form of the pyramid this process holds (see Shade): AO,
/// shadows, and both in one pass (on a SurfacePyramid a tile both reach is built once).
struct PyramidKernels
{
  std::function<vao::Status(const SurfacePoints& points, float* out)> occlusion;
  std::function<vao::Status(
    const SurfacePoints& points, const std::array<double, 3>& light, float* out)>
    shadow;
  std::function<vao::Status(const SurfacePoints& points, const std::array<double, 3>& light,
    float* occlusion, float* shadow)>
    both;
};

/// The two queries on `source`: in one process the SurfacePyramid, whose finest levels are
/// tiles built as the points reach them; under MPI the whole levels of this process's
/// piece (a vector of MomentLevel), the coarsest shared by all.
template <class Source>
PyramidKernels Kernels(Source& source, const Sampling& s)
{
  PyramidKernels kernels;
  kernels.occlusion = [&source, &s](const SurfacePoints& points, float* out)
  {
    return points.Run(
      [&](auto xyz, auto normals)
      {
        return vao::surfaceAmbientOcclusion(source, s.volume, s.origin, s.spacing, xyz, normals,
          points.count, s.parameters, out, s.execution);
      });
  };
  kernels.shadow = [&source, &s](
                     const SurfacePoints& points, const std::array<double, 3>& light, float* out)
  {
    return points.Run(
      [&](auto xyz, auto normals)
      {
        return vao::surfaceShadow(
          source, xyz, normals, points.count, light, s.parameters, out, s.execution);
      });
  };
  kernels.both = [&source, &s, kernels](const SurfacePoints& points,
                   const std::array<double, 3>& light, float* occlusion, float* shadow)
  {
    if constexpr (std::is_same<Source, vao::SurfacePyramid>::value)
      return points.Run(
        [&](auto xyz, auto normals)
        {
          return vao::surfaceOcclusionAndShadow(source, s.volume, s.origin, s.spacing, xyz, normals,
            points.count, light, s.parameters, occlusion, shadow, s.execution);
        });
    const vao::Status status = kernels.occlusion(points, occlusion);
    return status.ok ? kernels.shadow(points, light, shadow) : status;
  };
  return kernels;
}
} // namespace

namespace
{
/// The time step of a data object (DATA_TIME_STEP), NaN when it has none.
double DataTime(vtkDataObject* data)
{
  vtkInformation* info = data->GetInformation();
  return info && info->Has(vtkDataObject::DATA_TIME_STEP())
    ? info->Get(vtkDataObject::DATA_TIME_STEP())
    : std::nan("");
}
} // namespace

/// The pyramid of the last volume, and what it was built from: the array (and its MTime,
/// which VTK bumps whenever a source refills it or a user calls array->Modified()) on the
/// volume's grid. Not the volume object's MTime: ParaView hands the filter a shallow copy
/// of the reader's output that is made again on every update (vtkPVPostFilter), which
/// rebuilt the pyramid on every light move. And the volume's time step: an in situ adaptor
/// may refill the same array at each step without marking it modified.
struct vtkIsosurfaceAmbientOcclusion::Cache
{
  // One process: level 0 kept only where the surfaces sample it. Under MPI: the whole
  // levels of this process's piece (ShareCoarsestLevel replaces the coarsest).
  vao::SurfacePyramid surface;
  std::vector<vao::MomentLevel> levels;
  std::array<int, 6> extent{};
  vtkDataArray* array = nullptr;
  vtkMTimeType arrayTime = 0;
  double dataTime = std::nan(""); // the volume's DATA_TIME_STEP; NaN when it has none
  int component = -1;
  int numberOfLevels = 0;
  bool halfResolution = false;
  // The input scalars as the kernels read them (for the half-voxel-inside query).
  vtkAmbientOcclusionArrayInput::ScalarVolume scalars;
  std::array<double, 3> origin{};
  std::array<double, 3> spacing{};
  // The frame the current surface's points are in (PlaceSurface: the volume's,
  // scalars.frame, or the image's axes): its points, normals and the light are turned
  // from it into the volume's axis-aligned one.
  vtkAmbientOcclusionFrame::Frame surfaceFrame;
  // The last AmbientOcclusion, which does not depend on the light: a light move reuses it
  // while the surface, the query and the pyramid stay (SurfaceKey).
  vtkSmartPointer<vtkFloatArray> occlusion;
  SurfaceKey occlusionKey;
};

//------------------------------------------------------------------------------
vtkIsosurfaceAmbientOcclusion::vtkIsosurfaceAmbientOcclusion()
  : Controller(vtkMultiProcessController::GetGlobalController())
  , Pyramid(new Cache)
{
  this->SetNumberOfInputPorts(2);
  this->SetInputArrayToProcess(
    0, 1, 0, vtkDataObject::FIELD_ASSOCIATION_POINTS, vtkDataSetAttributes::SCALARS);
}

vtkIsosurfaceAmbientOcclusion::~vtkIsosurfaceAmbientOcclusion() = default;

//------------------------------------------------------------------------------
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
vtkTypeBool vtkIsosurfaceAmbientOcclusion::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // The output is like the surface: polygonal data, or a composite data set of it.
  if (request->Has(vtkDemandDrivenPipeline::REQUEST_DATA_OBJECT()))
    return vtkAmbientOcclusionComposite::RequestDataObject(
      inputVector, outputVector, "vtkPolyData");
  return this->Superclass::ProcessRequest(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------
int vtkIsosurfaceAmbientOcclusion::FillInputPortInformation(int port, vtkInformation* info)
{
  if (port == 0)
    vtkAmbientOcclusionComposite::AcceptSurfacesAndComposites(info);
  else
    vtkAmbientOcclusionComposite::AcceptImagesAndComposites(info);
  return 1;
}

//------------------------------------------------------------------------------
int vtkIsosurfaceAmbientOcclusion::FillOutputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkDataObject"); // made by ProcessRequest
  return 1;
}

//------------------------------------------------------------------------------
int vtkIsosurfaceAmbientOcclusion::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector*)
{
  // One process reads the whole volume. Several read their piece grown by the reach of
  // the finer levels' queries; the coarsest level is shared (UpdateDistributedPyramid).
  vtkInformation* volumeInfo = inputVector[1]->GetInformationObject(0);
  if (vtkAmbientOcclusionComposite::IsComposite(volumeInfo))
    return 1; // the piece request passes on as it is; the pieces are gathered in RequestData
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
  this->PieceOf(whole, piece);
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
    why << vtkAmbientOcclusionRequest::ThreadsError(this->NumberOfThreads);
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
  return vtkAmbientOcclusionRequest::Distributed(this->Controller) && this->NumberOfLevels >= 2;
}

//------------------------------------------------------------------------------
void vtkIsosurfaceAmbientOcclusion::PieceOf(const int whole[6], int piece[6]) const
{
  Extents::PieceOfWhole(
    this->Controller->GetLocalProcessId(), this->Controller->GetNumberOfProcesses(), whole, piece);
}

//------------------------------------------------------------------------------
void vtkIsosurfaceAmbientOcclusion::VolumeExtentOf(
  const int whole[6], const double spacing[3], const int piece[6], int ext[6]) const
{
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
int vtkIsosurfaceAmbientOcclusion::AdoptHeldPiece(vtkPolyData* surface, vtkImageData*& volume,
  const int whole[6], int piece[6], vtkImageData* fetched)
{
  // Whether this process's surface points lie in its piece (a Contour of it), with the
  // slack of a surface piece's ghost cells; on an axis-aligned grid only.
  int held[6] = { 0, -1, 0, -1, 0, -1 };
  if (volume->GetNumberOfPoints() > 0)
    volume->GetExtent(held);
  const bool inside = surface->GetNumberOfPoints() == 0 ||
    vtkAmbientOcclusionFrame::SurfaceWithinExtent(surface, volume, held, whole, kSurfaceSlack);
  // The coarsest level is assembled from every piece's: they must fill the whole extent.
  std::vector<double> mine(held, held + 6), all;
  std::vector<int> owners;
  vtkAmbientOcclusionCollectives::GatherLists(this->Controller, mine, 6, all, owners);
  bool complete = false;
  vtkAmbientOcclusionCollectives::PlanTransfers(std::vector<int>(all.begin(), all.end()), owners,
    std::vector<int>(whole, whole + 6), { 0 }, complete);
  if (vtkAmbientOcclusionCollectives::GlobalMax(this->Controller, complete && inside ? 0.0 : 1.0) >
    0.0)
    return 0;
  std::copy(held, held + 6, piece);
  int ext[6];
  this->VolumeExtentOf(whole, volume->GetSpacing(), piece, ext);
  std::string error;
  vtkImageData* covered = vtkAmbientOcclusionCollectives::CoverNeededExtent(
    this->Controller, volume, whole, ext, fetched, error);
  if (!covered)
  {
    vtkErrorMacro(<< error);
    return -1;
  }
  if (!Extents::EmptyExtent(ext) && !std::equal(ext, ext + 6, covered->GetExtent()))
  {
    vtkNew<vtkImageData> cropped;
    Extents::CopyRequestedExtent(covered, cropped, ext);
    fetched->ShallowCopy(cropped);
    covered = fetched;
  }
  volume = covered;
  return 1;
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
  if (vtkAmbientOcclusionComposite::IsComposite(inputVector[0]->GetInformationObject(0)) ||
    vtkAmbientOcclusionComposite::IsComposite(inputVector[1]->GetInformationObject(0)))
    return vtkAmbientOcclusionComposite::ProduceOnSurface(this, this->Controller, inputVector,
      outputVector,
      [&](vtkInformationVector** in, vtkInformationVector* out)
      { return this->RequestData(nullptr, in, out); });
  return vtkAmbientOcclusionRequest::ProduceOutput(this, outputVector,
    "try StartAtHalfResolution, fewer NumberOfLevels, or more MPI ranks.",
    [&] { return this->ProduceOutput(inputVector, outputVector); });
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
  int piece[6];
  std::copy(whole, whole + 6, piece);
  if (distributed)
    this->PieceOf(whole, piece);
  if (distributed && !Extents::CanProduceSubExtent(inputVector[1]->GetInformationObject(0)))
  {
    if (!this->CheckParameters()) // the same answer on every process, before the collectives
    {
      return 1;
    }
    // Pieces handed over (in situ): each process keeps its own, with its reach.
    const int adopted = this->AdoptHeldPiece(surface, volume, whole, piece, fetched);
    if (adopted < 0)
    {
      return 1;
    }
    if (adopted == 0)
    {
      // A reader that does not split, or a surface away from the pieces: every process
      // with surface points takes the whole volume from the processes that hold it, and
      // shades its points as one process does.
      const int none[6] = { 0, -1, 0, -1, 0, -1 };
      std::string error;
      volume = vtkAmbientOcclusionCollectives::CoverNeededExtent(this->Controller, volume, whole,
        surface->GetNumberOfPoints() > 0 ? whole : none, fetched, error);
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
      distributed = false;
    }
    chosen = this->GetInputArrayToProcess(0, volume);
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
  if (!distributed)
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

//------------------------------------------------------------------------------
bool vtkIsosurfaceAmbientOcclusion::UpdatePyramid(vtkImageData* volume, vtkDataArray* chosen)
{
  Cache& cache = *this->Pyramid;
  const int* extent = volume->GetExtent();
  const double* h = volume->GetSpacing();
  const double* d = volume->GetDirectionMatrix()->GetData();
  const bool sameGrid = std::equal(extent, extent + 6, cache.extent.begin()) &&
    cache.origin == PyramidImages::ExtentOrigin(volume) &&
    cache.spacing == std::array<double, 3>{ h[0], h[1], h[2] } &&
    std::equal(d, d + 9, cache.scalars.frame.direction.begin());
  const double dataTime = DataTime(volume);
  const bool sameTime =
    dataTime == cache.dataTime || (std::isnan(dataTime) && std::isnan(cache.dataTime));
  const bool fresh = chosen && cache.array == chosen && cache.arrayTime == chosen->GetMTime() &&
    sameTime && sameGrid && cache.component == this->Component &&
    cache.numberOfLevels == this->NumberOfLevels &&
    cache.halfResolution == (this->StartAtHalfResolution != 0) && !cache.surface.empty();
  if (fresh)
  {
    return true;
  }
  cache.levels.clear();
  cache.surface.clear();
  std::string error;
  if (!Extents::CheckWholeExtent(volume->GetExtent(), error) ||
    !PrepareScalars(this, chosen, volume, this->Component, cache.scalars, error) ||
    !PyramidImages::BuildPyramid(cache.scalars, volume, this->PyramidRequest(),
      Execution(this, this->NumberOfThreads, 0.0, kPyramidShare), cache.surface, error))
  {
    cache.surface.clear();
    if (!error.empty())
    {
      vtkErrorMacro(<< error);
    }
    return false;
  }
  PyramidImages::WarnOfCoarseMeans(this, cache.surface.levels());
  cache.origin = PyramidImages::ExtentOrigin(volume);
  cache.spacing = { h[0], h[1], h[2] };
  std::copy(extent, extent + 6, cache.extent.begin());
  cache.array = chosen;
  cache.arrayTime = chosen ? chosen->GetMTime() : 0;
  cache.dataTime = dataTime;
  cache.component = this->Component;
  cache.numberOfLevels = this->NumberOfLevels;
  cache.halfResolution = this->StartAtHalfResolution != 0;
  ++this->PyramidBuilds;
  return true;
}

//------------------------------------------------------------------------------
bool vtkIsosurfaceAmbientOcclusion::UpdateDistributedPyramid(
  vtkImageData* volume, vtkDataArray* chosen, const int whole[6], const int piece[6])
{
  Cache& cache = *this->Pyramid;
  cache.levels.clear();
  cache.surface.clear();
  cache.array = nullptr; // not reused: the pieces follow the decomposition
  std::string error;
  int expected[6];
  this->VolumeExtentOf(whole, volume->GetSpacing(), piece, expected);
  const bool empty = Extents::EmptyExtent(piece);
  if (!empty && !std::equal(expected, expected + 6, volume->GetExtent()))
  {
    error = "The volume input delivered another extent than this process's piece and its reach: "
            "under MPI, "
            "feed the Volume input from its own reader.";
  }
  else if (!empty && Extents::CheckWholeExtent(whole, error) &&
    PrepareScalars(this, chosen, volume, this->Component, cache.scalars, error))
  {
    PyramidImages::BuildPyramid(cache.scalars, volume, this->PyramidRequest(),
      Execution(this, this->NumberOfThreads, 0.0, kPyramidShare), cache.levels, error);
  }
  // Every process learns whether any failed before the coarsest level is shared.
  const bool failed = !error.empty() || (!empty && cache.levels.empty());
  if (vtkAmbientOcclusionCollectives::GlobalMax(this->Controller, failed ? 1.0 : 0.0) > 0.0)
  {
    vtkErrorMacro(<< (error.empty()
                      ? std::string("The pyramid failed on another process (see its message).")
                      : error));
    cache.levels.clear();
    return false;
  }
  PyramidImages::WarnOfCoarseMeans(this, cache.levels);
  this->ShareCoarsestLevel(volume, whole, expected, piece);
  if (empty)
  {
    return false;
  }
  const double* h = volume->GetSpacing();
  cache.origin = PyramidImages::ExtentOrigin(volume);
  cache.spacing = { h[0], h[1], h[2] };
  ++this->PyramidBuilds;
  return true;
}

//------------------------------------------------------------------------------
void vtkIsosurfaceAmbientOcclusion::ShareCoarsestLevel(
  vtkImageData* volume, const int whole[6], const int inputExt[6], const int piece[6])
{
  // This piece's voxels of the coarsest level go to every process; the whole level is
  // assembled from them (they overlap where pieces share a face).
  Cache& cache = *this->Pyramid;
  const bool half = this->StartAtHalfResolution != 0;
  const int last = this->NumberOfLevels - 1;
  const int step = (half ? 2 : 1) << last;
  vtkSmartPointer<vtkImageData> part;
  if (!cache.levels.empty())
  {
    part = PyramidImages::LevelPiece(cache.levels[last], whole, inputExt, piece, step);
  }
  vao::MomentLevel coarsest = PyramidImages::WholeLevelGeometry(volume, whole, step);
  vtkAmbientOcclusionCollectives::GatherLevel(this->Controller, part, coarsest);
  // Every process treats the same samples as flat: the largest rounding bound of any piece.
  const double rounding = vtkAmbientOcclusionCollectives::GlobalMax(
    this->Controller, cache.levels.empty() ? 0.0 : cache.levels[0].roundingVariance);
  if (cache.levels.empty())
  {
    return; // an empty piece: nothing of its own to sample
  }
  coarsest.kernelRadius = cache.levels[last].kernelRadius;
  cache.levels[last] = std::move(coarsest);
  for (vao::MomentLevel& level : cache.levels)
  {
    level.roundingVariance = rounding;
  }
  // The shadows' march stops at the whole volume's border, not at this piece's.
  const vao::MomentLevel base = PyramidImages::WholeLevelGeometry(volume, whole, half ? 2 : 1);
  for (int a = 0; a < 3; ++a)
  {
    cache.levels[0].wholeBounds[2 * a] = base.origin[a];
    cache.levels[0].wholeBounds[2 * a + 1] = base.origin[a] + (base.dims[a] - 1) * base.spacing[a];
  }
}

//------------------------------------------------------------------------------
void vtkIsosurfaceAmbientOcclusion::PlaceSurface(vtkPolyData* surface, double bounds[6])
{
  Cache& cache = *this->Pyramid;
  cache.surfaceFrame = cache.scalars.frame;
  if (!cache.scalars.frame.identity && surface->GetNumberOfPoints() > 0 &&
    vtkAmbientOcclusionFrame::SurfaceAlongImageAxes(
      surface, cache.scalars.view, cache.scalars.frame, cache.origin, cache.spacing))
  {
    cache.surfaceFrame = vtkAmbientOcclusionFrame::Frame{};
    vtkWarningMacro(
      << "The surface lies on the volume's iso-surface only with the volume's direction matrix "
         "ignored, as vtkContourFilter and ParaView 5.11's Contour extract it: its points, normals "
         "and LightDirection are taken along the image's axes.");
  }
  vtkAmbientOcclusionFrame::SurfaceBoundsInFrame(surface, cache.surfaceFrame, bounds);
}

//------------------------------------------------------------------------------
bool vtkIsosurfaceAmbientOcclusion::Shade(vtkPolyData* surface, vtkPolyData* output)
{
  Cache& cache = *this->Pyramid;
  const Sampling sampling{ cache.scalars.view, cache.origin, cache.spacing, this->Parameters(),
    Execution(this, this->NumberOfThreads, kPyramidShare, 1.0) };
  const SurfaceKey key(surface, sampling.parameters, this->PyramidBuilds);
  const bool newOcclusion = !cache.occlusion || !(cache.occlusionKey == key);
  const vtkAmbientOcclusionFrame::Frame& frame = cache.surfaceFrame; // PlaceSurface's
  SurfacePoints points;
  std::string error;
  if (!vtkAmbientOcclusionArrayInput::ReadSurfacePoints(surface, frame, cache.scalars, cache.origin,
        cache.spacing, newOcclusion || this->ComputeShadows, points, error))
  {
    vtkErrorMacro(<< error);
    return false;
  }
  if (points.replacedNormals > 0)
  {
    vtkWarningMacro(<< points.replacedNormals << " of the surface's " << points.count
                    << " point normals are zero or not finite: those points take the "
                       "volume's gradient (or their polygons' normal) instead.");
  }
  // The serial/MPI decision, made once: UpdatePyramid (one process) built the tiled
  // pyramid, UpdateDistributedPyramid (MPI) the whole levels of this process's piece.
  const PyramidKernels kernels =
    cache.surface.empty() ? Kernels(cache.levels, sampling) : Kernels(cache.surface, sampling);
  vtkNew<vtkFloatArray> shadow;
  if (this->ComputeShadows)
  {
    shadow->SetName("Shadow");
    vtkAmbientOcclusionMemory::Allocate(shadow, points.count, "the Shadow output");
  }
  const std::array<double, 3> light = frame.identity
    ? std::array<double, 3>{ this->LightDirection[0], this->LightDirection[1],
        this->LightDirection[2] }
    : frame.VectorToImage(this->LightDirection);
  vao::Status status = vao::Status::success();
  if (newOcclusion)
  {
    cache.occlusion = nullptr;
    vtkNew<vtkFloatArray> occlusion;
    occlusion->SetName("AmbientOcclusion");
    vtkAmbientOcclusionMemory::Allocate(occlusion, points.count, "the AmbientOcclusion output");
    status = this->ComputeShadows
      ? kernels.both(points, light, occlusion->GetPointer(0), shadow->GetPointer(0))
      : kernels.occlusion(points, occlusion->GetPointer(0));
    if (status.ok)
    {
      cache.occlusion = occlusion;
      cache.occlusionKey = key;
    }
  }
  else if (this->ComputeShadows)
  {
    status = kernels.shadow(points, light, shadow->GetPointer(0));
  }
  if (!status.ok)
  {
    error = vtkAmbientOcclusionArrayInput::KernelError(
      status, cache.scalars, "Isosurface ambient occlusion failed");
    if (!error.empty())
    {
      vtkErrorMacro(<< error);
    }
    return false;
  }
  output->GetPointData()->AddArray(cache.occlusion);
  if (this->ComputeShadows)
  {
    output->GetPointData()->AddArray(shadow);
  }
  return true;
}
