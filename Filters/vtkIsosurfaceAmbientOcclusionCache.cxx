// vtkIsosurfaceAmbientOcclusion, what it keeps between updates: the moment pyramid (built
// once per volume, serially or as distributed pieces with a shared coarsest level) and the
// last AmbientOcclusion (which a light move reuses), and the shading that samples them.
#include "vtkIsosurfaceAmbientOcclusion.h"

#include "vtkAmbientOcclusionArrayInput.h"
#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionExtents.h"
#include "vtkAmbientOcclusionFrame.h"
#include "vtkAmbientOcclusionMemory.h"
#include "vtkAmbientOcclusionPyramidImages.h"

#include "vao/VarianceOcclusionMap.h"

#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkMatrix3x3.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <string>
#include <tuple>
#include <type_traits>
#include <vector>

namespace Extents = vtkAmbientOcclusionExtents;
namespace PyramidImages = vtkAmbientOcclusionPyramidImages;
using vtkAmbientOcclusionArrayInput::ExecutionOf;
using vtkAmbientOcclusionArrayInput::PrepareScalars;
using vtkAmbientOcclusionArrayInput::SurfacePoints;

namespace
{
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

// PlaceSurface's guess of the frame a surface is in: the workaround for VTK 9.2's
// vtkContourFilter and vtkSynchronizedTemplates3D (ParaView 5.11's Contour), which ignore an
// oriented image's direction matrix. VTK places an oriented image's voxels at origin + D
// (spacing index); vtkFlyingEdges3D and vtkMarchingCubes put a contour there, while those
// two leave it along the image's axes. A contour's points lie on grid edges, where the
// trilinear volume takes the iso value: the frame in which the sampled values agree is the
// surface's. The axes win only where the physical frame's values clearly disagree: the
// points of a physical surface read along the axes may all fall in flat air, and agree
// there too.
/// The points read: every (n / kFrameSamples)-th of n, so all of a surface under 1024
/// points and 512 to 768 of a larger one; enough for the medians, few beside the shading.
constexpr vtkIdType kFrameSamples = 512;
/// The physical frame's values disagree: their median deviation exceeds this fraction of
/// the spread of every value read (both frames').
constexpr double kFrameDisagreement = 1e-4;
/// The axes' values agree: their median deviation is below this fraction of the
/// physical frame's.
constexpr double kAxesAgreement = 1e-3;

/// The median distance of the values from their median: near 0 when nearly all agree.
double MedianDeviation(std::vector<double> values)
{
  const auto middle = values.begin() + values.size() / 2;
  std::nth_element(values.begin(), middle, values.end());
  const double median = *middle;
  for (double& v : values)
    v = std::abs(v - median);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

/// Whether the points of `surface` (some) lie on the iso-surface of the oriented volume
/// only along the image's axes, its direction matrix ignored (see kFrameSamples).
bool AlongImageAxes(vtkPolyData* surface, const vtkAmbientOcclusionArrayInput::ScalarVolume& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing)
{
  const vtkIdType n = surface->GetNumberOfPoints();
  std::vector<double> inFrame, alongAxes;
  for (vtkIdType i = 0; i < n; i += std::max<vtkIdType>(1, n / kFrameSamples))
  {
    const double* p = surface->GetPoint(i);
    inFrame.push_back(
      vao::sampleVolume(volume.view, origin, spacing, volume.frame.PointToImage(p)));
    alongAxes.push_back(vao::sampleVolume(volume.view, origin, spacing, { p[0], p[1], p[2] }));
  }
  const auto [low, high] = std::minmax_element(inFrame.begin(), inFrame.end());
  const auto [lowAxes, highAxes] = std::minmax_element(alongAxes.begin(), alongAxes.end());
  const double spread = std::max(*high, *highAxes) - std::min(*low, *lowAxes);
  const double disagreement = MedianDeviation(inFrame);
  return disagreement > kFrameDisagreement * spread &&
    MedianDeviation(alongAxes) < kAxesAgreement * disagreement;
}

/// The bounds of the surface's points in the volume's axis-aligned frame (from `frame`).
void BoundsInFrame(
  vtkPolyData* surface, const vtkAmbientOcclusionFrame::Frame& frame, double bounds[6])
{
  if (frame.identity)
  {
    surface->GetBounds(bounds);
    return;
  }
  for (int a = 0; a < 3; ++a)
  {
    bounds[2 * a] = std::numeric_limits<double>::infinity();
    bounds[2 * a + 1] = -bounds[2 * a];
  }
  const vtkIdType n = surface->GetNumberOfPoints();
  for (vtkIdType i = 0; i < n; ++i)
  {
    const std::array<double, 3> p = frame.PointToImage(surface->GetPoint(i));
    for (int a = 0; a < 3; ++a)
    {
      bounds[2 * a] = std::min(bounds[2 * a], p[a]);
      bounds[2 * a + 1] = std::max(bounds[2 * a + 1], p[a]);
    }
  }
}

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

/// The pyramid of the last volume, and what it was built from: the array (and its MTime,
/// which VTK bumps whenever a source refills it or a user calls array->Modified()) on the
/// volume's grid. Not the volume object's MTime: ParaView hands the filter a shallow copy
/// of the reader's output that is made again on every update (vtkPVPostFilter), which
/// rebuilt the pyramid on every light move.
struct vtkIsosurfaceAmbientOcclusion::Cache
{
  // One process: level 0 kept only where the surfaces sample it. Under MPI: the whole
  // levels of this process's piece (ShareCoarsestLevel replaces the coarsest).
  vao::SurfacePyramid surface;
  std::vector<vao::MomentLevel> levels;
  std::array<int, 6> extent{};
  vtkDataArray* array = nullptr;
  vtkMTimeType arrayTime = 0;
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
  const bool fresh = chosen && cache.array == chosen && cache.arrayTime == chosen->GetMTime() &&
    sameGrid && cache.component == this->Component &&
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
      ExecutionOf(this, this->NumberOfThreads, 0.0, kPyramidShare), cache.surface, error))
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
  cache.component = this->Component;
  cache.numberOfLevels = this->NumberOfLevels;
  cache.halfResolution = this->StartAtHalfResolution != 0;
  ++this->PyramidBuilds;
  return true;
}

//------------------------------------------------------------------------------
bool vtkIsosurfaceAmbientOcclusion::UpdateDistributedPyramid(
  vtkImageData* volume, vtkDataArray* chosen, const int whole[6], int piece[6])
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
      ExecutionOf(this, this->NumberOfThreads, 0.0, kPyramidShare), cache.levels, error);
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
    AlongImageAxes(surface, cache.scalars, cache.origin, cache.spacing))
  {
    cache.surfaceFrame = vtkAmbientOcclusionFrame::Frame{};
    vtkWarningMacro(
      << "The surface lies on the volume's iso-surface only with the volume's direction matrix "
         "ignored, as vtkContourFilter and ParaView 5.11's Contour extract it: its points, normals "
         "and LightDirection are taken along the image's axes.");
  }
  BoundsInFrame(surface, cache.surfaceFrame, bounds);
}

//------------------------------------------------------------------------------
bool vtkIsosurfaceAmbientOcclusion::Shade(vtkPolyData* surface, vtkPolyData* output)
{
  Cache& cache = *this->Pyramid;
  const Sampling sampling{ cache.scalars.view, cache.origin, cache.spacing, this->Parameters(),
    ExecutionOf(this, this->NumberOfThreads, kPyramidShare, 1.0) };
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
