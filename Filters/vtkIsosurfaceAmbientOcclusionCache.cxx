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
#include <limits>
#include <string>
#include <tuple>
#include <vector>

namespace Extents = vtkAmbientOcclusionExtents;
namespace PyramidImages = vtkAmbientOcclusionPyramidImages;
using vtkAmbientOcclusionArrayInput::ExecutionOf;
using vtkAmbientOcclusionArrayInput::PrepareScalars;

namespace
{
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
    , query{ static_cast<double>(p.query), p.isoValue, p.offsetFactor, static_cast<double>(p.estimator),
      static_cast<double>(p.combination), static_cast<double>(p.levels) }
    , pyramidBuilds(builds)
  {
    this->pointsTime = this->points ? this->points->GetMTime() : 0;
    this->normalsTime = this->normals ? this->normals->GetMTime() : 0;
  }

  bool operator==(const SurfaceKey& o) const
  {
    return std::tie(this->points, this->pointsTime, this->normals, this->normalsTime, this->count, this->query,
             this->pyramidBuilds) ==
      std::tie(o.points, o.pointsTime, o.normals, o.normalsTime, o.count, o.query, o.pyramidBuilds);
  }
};
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
    cache.origin == PyramidImages::ExtentOrigin(volume) && cache.spacing == std::array<double, 3>{ h[0], h[1], h[2] } &&
    std::equal(d, d + 9, cache.scalars.frame.direction.begin());
  const bool fresh = chosen && cache.array == chosen && cache.arrayTime == chosen->GetMTime() && sameGrid &&
    cache.component == this->Component &&
    cache.numberOfLevels == this->NumberOfLevels && cache.halfResolution == (this->StartAtHalfResolution != 0) &&
    !cache.surface.empty();
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
      ExecutionOf(this, this->NumberOfThreads), cache.surface, error))
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
    error = "The volume input delivered another extent than this process's piece and its reach: under MPI, "
            "feed the Volume input from its own reader.";
  }
  else if (!empty && Extents::CheckWholeExtent(whole, error) &&
    PrepareScalars(this, chosen, volume, this->Component, cache.scalars, error))
  {
    PyramidImages::BuildPyramid(cache.scalars, volume, this->PyramidRequest(),
      ExecutionOf(this, this->NumberOfThreads), cache.levels, error);
  }
  // Every process learns whether any failed before the coarsest level is shared.
  const bool failed = !error.empty() || (!empty && cache.levels.empty());
  if (vtkAmbientOcclusionCollectives::GlobalMax(this->Controller, failed ? 1.0 : 0.0) > 0.0)
  {
    vtkErrorMacro(<< (error.empty() ? std::string("The pyramid failed on another process (see its message).") : error));
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
  // VTK places an oriented image's voxels at origin + D (spacing index); vtkFlyingEdges3D
  // and vtkMarchingCubes put a contour there, while vtkContourFilter and
  // vtkSynchronizedTemplates3D of VTK 9.2 (ParaView 5.11's Contour) leave it along the
  // image's axes. A contour's points lie on grid edges, where the trilinear volume takes
  // the iso value: the frame in which the sampled values agree is the surface's. The
  // axes win only where the physical frame's values clearly disagree: the points of a
  // physical surface read along the axes may all fall in flat air, and agree there too.
  Cache& cache = *this->Pyramid;
  const vtkAmbientOcclusionFrame::Frame& volumeFrame = cache.scalars.frame;
  cache.surfaceFrame = volumeFrame;
  const vtkIdType n = surface->GetNumberOfPoints();
  if (!volumeFrame.identity && n > 0)
  {
    std::vector<double> inFrame, alongAxes;
    for (vtkIdType i = 0; i < n; i += std::max<vtkIdType>(1, n / 512))
    {
      const double* p = surface->GetPoint(i);
      inFrame.push_back(vao::sampleVolume(cache.scalars.view, cache.origin, cache.spacing, volumeFrame.PointToImage(p)));
      alongAxes.push_back(vao::sampleVolume(cache.scalars.view, cache.origin, cache.spacing, { p[0], p[1], p[2] }));
    }
    const auto [low, high] = std::minmax_element(inFrame.begin(), inFrame.end());
    const auto [lowAxes, highAxes] = std::minmax_element(alongAxes.begin(), alongAxes.end());
    const double spread = std::max(*high, *highAxes) - std::min(*low, *lowAxes);
    const double disagreement = MedianDeviation(inFrame);
    if (disagreement > 1e-4 * spread && MedianDeviation(alongAxes) < 1e-3 * disagreement)
    {
      cache.surfaceFrame = vtkAmbientOcclusionFrame::Frame{};
      vtkWarningMacro(<< "The surface lies on the volume's iso-surface only with the volume's direction matrix "
                         "ignored, as vtkContourFilter and ParaView 5.11's Contour extract it: its points, normals "
                         "and LightDirection are taken along the image's axes.");
    }
  }
  const vtkAmbientOcclusionFrame::Frame& frame = cache.surfaceFrame;
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

//------------------------------------------------------------------------------
bool vtkIsosurfaceAmbientOcclusion::Shade(vtkPolyData* surface, vtkPolyData* output)
{
  Cache& cache = *this->Pyramid;
  const vao::SurfaceOcclusionParameters parameters = this->Parameters();
  const vao::Execution execution = ExecutionOf(this, this->NumberOfThreads);
  const SurfaceKey key(surface, parameters, this->PyramidBuilds);
  const bool newOcclusion = !cache.occlusion || !(cache.occlusionKey == key);
  // The points and normals as the kernels read them, only when a kernel runs (with the AO
  // kept and shadows off there is nothing to compute): float arrays in place (what
  // contours give), anything else as a double copy.
  const vtkIdType n = surface->GetNumberOfPoints();
  vtkDataArray* givenNormals = vtkAmbientOcclusionArrayInput::GivenNormals(surface);
  if (givenNormals && givenNormals->GetNumberOfTuples() < n)
  {
    vtkErrorMacro(<< "The surface's normals (\"" << (givenNormals->GetName() ? givenNormals->GetName() : "")
                  << "\") have " << givenNormals->GetNumberOfTuples() << " tuples for " << n
                  << " points: give one normal per point, or none (then they come from the volume's gradient).");
    return false;
  }
  vtkFloatArray* floatPoints = vtkFloatArray::SafeDownCast(surface->GetPoints() ? surface->GetPoints()->GetData() : nullptr);
  vtkFloatArray* floatNormals = vtkFloatArray::SafeDownCast(givenNormals);
  const vtkAmbientOcclusionFrame::Frame& frame = cache.surfaceFrame; // PlaceSurface's
  const bool inPlace = floatPoints && floatNormals && frame.identity;
  std::vector<double> points, normals;
  std::string error;
  if (!inPlace && (newOcclusion || this->ComputeShadows))
  {
    points.resize(static_cast<size_t>(3 * n));
    for (vtkIdType i = 0; i < n; ++i)
    {
      surface->GetPoint(i, &points[3 * i]);
      if (!frame.identity)
      {
        const std::array<double, 3> p = frame.PointToImage(&points[3 * i]);
        std::copy(p.begin(), p.end(), points.begin() + 3 * i);
      }
    }
    if (!vtkAmbientOcclusionArrayInput::SurfaceNormals(
          surface, points, frame, cache.scalars, cache.origin, cache.spacing, normals, error))
    {
      vtkErrorMacro(<< error);
      return false;
    }
  }
  // One call for either form of the points.
  const auto run = [&](auto&& kernel) {
    return inPlace ? kernel(static_cast<const float*>(floatPoints->GetPointer(0)),
                       static_cast<const float*>(floatNormals->GetPointer(0)))
                   : kernel(static_cast<const double*>(points.data()), static_cast<const double*>(normals.data()));
  };
  vao::Status status = vao::Status::success();
  if (newOcclusion)
  {
    cache.occlusion = nullptr;
    vtkNew<vtkFloatArray> occlusion;
    occlusion->SetName("AmbientOcclusion");
    vtkAmbientOcclusionMemory::Allocate(occlusion, n, "the AmbientOcclusion output");
    status = run([&](auto p, auto nn) {
      return cache.surface.empty()
        ? vao::surfaceAmbientOcclusion(cache.levels, cache.scalars.view, cache.origin, cache.spacing, p, nn, n,
            parameters, occlusion->GetPointer(0), execution)
        : vao::surfaceAmbientOcclusion(cache.surface, cache.scalars.view, cache.origin, cache.spacing, p, nn, n,
            parameters, occlusion->GetPointer(0), execution);
    });
    if (status.ok)
    {
      cache.occlusion = occlusion;
      cache.occlusionKey = key;
    }
  }
  vtkNew<vtkFloatArray> shadow;
  if (status.ok && this->ComputeShadows)
  {
    shadow->SetName("Shadow");
    vtkAmbientOcclusionMemory::Allocate(shadow, n, "the Shadow output");
    const std::array<double, 3> l = frame.identity
      ? std::array<double, 3>{ this->LightDirection[0], this->LightDirection[1], this->LightDirection[2] }
      : frame.VectorToImage(this->LightDirection);
    status = run([&](auto p, auto nn) {
      return cache.surface.empty()
        ? vao::surfaceShadow(cache.levels, p, nn, n, { l[0], l[1], l[2] }, parameters, shadow->GetPointer(0), execution)
        : vao::surfaceShadow(cache.surface, p, nn, n, { l[0], l[1], l[2] }, parameters, shadow->GetPointer(0), execution);
    });
  }
  if (!status.ok)
  {
    error = vtkAmbientOcclusionArrayInput::KernelError(status, cache.scalars, "Isosurface ambient occlusion failed");
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

