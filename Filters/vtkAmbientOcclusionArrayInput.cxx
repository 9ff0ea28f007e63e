#include "vtkAmbientOcclusionArrayInput.h"

#include "vao/Validation.h"
#include "vao/VarianceOcclusionMap.h"

#include "vtkAlgorithm.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <cmath>
#include <sstream>

namespace vtkAmbientOcclusionArrayInput
{
namespace
{

bool ToKernelType(int vtkType, vao::ScalarType& type)
{
  const bool longIs64 = sizeof(long) == 8;
  switch (vtkType)
  {
    case VTK_CHAR:
    case VTK_SIGNED_CHAR:
      type = vao::ScalarType::Int8;
      return true;
    case VTK_UNSIGNED_CHAR:
      type = vao::ScalarType::UInt8;
      return true;
    case VTK_SHORT:
      type = vao::ScalarType::Int16;
      return true;
    case VTK_UNSIGNED_SHORT:
      type = vao::ScalarType::UInt16;
      return true;
    case VTK_INT:
      type = vao::ScalarType::Int32;
      return true;
    case VTK_UNSIGNED_INT:
      type = vao::ScalarType::UInt32;
      return true;
    case VTK_LONG:
      type = longIs64 ? vao::ScalarType::Int64 : vao::ScalarType::Int32;
      return true;
    case VTK_LONG_LONG:
    case VTK_ID_TYPE:
      type = vao::ScalarType::Int64;
      return true;
    case VTK_UNSIGNED_LONG:
      type = longIs64 ? vao::ScalarType::UInt64 : vao::ScalarType::UInt32;
      return true;
    case VTK_UNSIGNED_LONG_LONG:
      type = vao::ScalarType::UInt64;
      return true;
    case VTK_FLOAT:
      type = vao::ScalarType::Float32;
      return true;
    case VTK_DOUBLE:
      type = vao::ScalarType::Float64;
      return true;
    default:
      return false;
  }
}

vtkDataArray* ChosenArray(vtkAlgorithm* algorithm, vtkDataArray* scalars, vtkImageData* input)
{
  const char* name = algorithm->GetInputArrayInformation(0)->Get(vtkDataObject::FIELD_NAME());
  if (!scalars && (!name || !*name))
  {
    // No array chosen (pvpython before the input was updated): the active point scalars.
    scalars = input->GetPointData()->GetScalars();
  }
  return scalars;
}

/// Points the view at component `picked` of the scalars, in place when their layout
/// allows, else through a copy unpacked to double.
void ViewComponent(vtkDataArray* scalars, int picked, ScalarVolume& volume)
{
  vao::VolumeView& view = volume.view;
  if (scalars->HasStandardMemoryLayout())
  {
    view.data = scalars->GetVoidPointer(picked);
    view.voxelStride = scalars->GetNumberOfComponents();
    return;
  }
  volume.unpacked.resize(static_cast<size_t>(scalars->GetNumberOfTuples()));
  for (vtkIdType i = 0; i < scalars->GetNumberOfTuples(); ++i)
  {
    volume.unpacked[i] = scalars->GetComponent(i, picked);
  }
  view.data = volume.unpacked.data();
  view.type = vao::ScalarType::Float64;
  view.voxelStride = 1;
}

} // namespace

bool PrepareScalars(vtkAlgorithm* algorithm, vtkDataArray* chosen, vtkImageData* input,
  int component, ScalarVolume& volume, std::string& error)
{
  vtkDataArray* scalars = ChosenArray(algorithm, chosen, input);
  if (!scalars)
  {
    error = "No numeric point array to process: choose a point-data array of the image "
            "(the Scalars property; string and cell arrays are not accepted).";
    return false;
  }
  volume.name = scalars->GetName() ? scalars->GetName() : "";
  if (input->GetPointData()->GetAbstractArray(scalars->GetName()) != scalars)
  {
    error =
      "Array '" + volume.name + "' is not a point-data array; the filter works on points (voxels).";
    return false;
  }
  error = PointCountError(scalars, input->GetNumberOfPoints());
  // Spacings, radii and distances are taken along the image's axes: they must be
  // orthogonal unit vectors in the physical frame.
  if (!error.empty() || !vtkAmbientOcclusionFrame::FrameOf(input, volume.frame, error))
    return false;
  const int components = scalars->GetNumberOfComponents();
  const int picked = component < 0 && components == 1 ? 0 : component;
  if (picked < 0 || picked >= components)
  {
    std::ostringstream why;
    why << "Array '" << volume.name << "' has " << components
        << " components; set Component to one of 0.." << components - 1 << " (got " << component
        << ").";
    error = why.str();
    return false;
  }
  if (!ToKernelType(scalars->GetDataType(), volume.view.type))
  {
    error =
      "Array '" + volume.name + "' has unsupported type " + scalars->GetDataTypeAsString() + ".";
    return false;
  }
  const int* dims = input->GetDimensions();
  const int* extent = input->GetExtent();
  volume.view.dims = { dims[0], dims[1], dims[2] };
  volume.firstVoxel = { extent[0], extent[2], extent[4] };
  ViewComponent(scalars, picked, volume);
  return true;
}

std::string PointCountError(vtkDataArray* array, vtkIdType points)
{
  if (!array || array->GetNumberOfTuples() == points)
    return std::string();
  std::ostringstream why;
  why << "Array '" << (array->GetName() ? array->GetName() : "") << "' has "
      << array->GetNumberOfTuples() << " tuples for the input's " << points
      << " points: a point array needs one tuple a point.";
  return why.str();
}

vtkDataArray* GivenNormals(vtkPolyData* surface)
{
  vtkDataArray* given = surface->GetPointData()->GetNormals();
  if (!given)
  {
    given = surface->GetPointData()->GetArray("Normals");
  }
  return given && given->GetNumberOfComponents() == 3 ? given : nullptr;
}

bool SurfaceNormals(vtkPolyData* surface, const std::vector<double>& points,
  const vtkAmbientOcclusionFrame::Frame& frame, const ScalarVolume& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing,
  std::vector<double>& normals, std::string& error)
{
  const vtkIdType n = surface->GetNumberOfPoints();
  normals.resize(static_cast<size_t>(3 * n));
  if (vtkDataArray* given = GivenNormals(surface))
  {
    for (vtkIdType i = 0; i < n; ++i)
    {
      given->GetTuple(i, &normals[3 * i]);
      if (!frame.identity)
      {
        const std::array<double, 3> turned = frame.VectorToImage(&normals[3 * i]);
        std::copy(turned.begin(), turned.end(), normals.begin() + 3 * i);
      }
    }
    return true;
  }
  for (vtkIdType i = 0; i < n; ++i)
  {
    const double* p = &points[3 * i];
    double g[3];
    for (int a = 0; a < 3; ++a)
    {
      std::array<double, 3> forward = { p[0], p[1], p[2] }, backward = forward;
      forward[a] += spacing[a];
      backward[a] -= spacing[a];
      g[a] = (vao::sampleVolume(volume.view, origin, spacing, forward) -
               vao::sampleVolume(volume.view, origin, spacing, backward)) /
        (2.0 * spacing[a]);
    }
    const double length = std::sqrt(g[0] * g[0] + g[1] * g[1] + g[2] * g[2]);
    if (!(length > 0.0))
    {
      std::ostringstream why;
      why << "The surface has no point normals and the volume's gradient is zero at point " << i
          << ": add normals (e.g. Contour with Compute Normals, or Generate Surface Normals).";
      error = why.str();
      return false;
    }
    for (int a = 0; a < 3; ++a)
    {
      normals[3 * i + a] = -g[a] / length;
    }
  }
  return true;
}

bool ReadSurfacePoints(vtkPolyData* surface, const vtkAmbientOcclusionFrame::Frame& frame,
  const ScalarVolume& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, bool needed, SurfacePoints& out, std::string& error)
{
  const vtkIdType n = surface->GetNumberOfPoints();
  out.count = n;
  vtkDataArray* givenNormals = GivenNormals(surface);
  if (givenNormals && givenNormals->GetNumberOfTuples() < n)
  {
    error = std::string("The surface's normals (\"") +
      (givenNormals->GetName() ? givenNormals->GetName() : "") + "\") have " +
      std::to_string(givenNormals->GetNumberOfTuples()) + " tuples for " + std::to_string(n) +
      " points: give one normal per point, or none (then they come from the volume's gradient).";
    return false;
  }
  vtkFloatArray* floatPoints =
    vtkFloatArray::SafeDownCast(surface->GetPoints() ? surface->GetPoints()->GetData() : nullptr);
  vtkFloatArray* floatNormals = vtkFloatArray::SafeDownCast(givenNormals);
  out.inPlace = floatPoints && floatNormals && frame.identity;
  if (out.inPlace)
  {
    out.floatPoints = floatPoints->GetPointer(0);
    out.floatNormals = floatNormals->GetPointer(0);
    return true;
  }
  if (!needed)
  {
    return true;
  }
  out.points.resize(static_cast<size_t>(3 * n));
  for (vtkIdType i = 0; i < n; ++i)
  {
    surface->GetPoint(i, &out.points[3 * i]);
    if (!frame.identity)
    {
      const std::array<double, 3> p = frame.PointToImage(&out.points[3 * i]);
      std::copy(p.begin(), p.end(), out.points.begin() + 3 * i);
    }
  }
  return SurfaceNormals(surface, out.points, frame, volume, origin, spacing, out.normals, error);
}

vao::Execution ExecutionOf(vtkAlgorithm* algorithm, int threads)
{
  vao::Execution execution;
  execution.threads = threads;
  execution.progress = [algorithm](double p) { algorithm->UpdateProgress(p); };
  execution.abortRequested = [algorithm] { return algorithm->GetAbortExecute() != 0; };
  return execution;
}

std::string NumberOfThreadsError(int threads)
{
  if (threads >= 0)
  {
    return {};
  }
  std::ostringstream why;
  why << "NumberOfThreads must be 0 (the cores available, divided among the MPI ranks of the node) "
         "or "
         "positive (got "
      << threads << ").";
  return why.str();
}

std::string NonFiniteError(vtkDataArray* array)
{
  vao::VolumeView view;
  if (!array || array->GetNumberOfTuples() <= 0 || !ToKernelType(array->GetDataType(), view.type) ||
    vao::scalarTypeIsIntegral(view.type))
  {
    return {};
  }
  if (!array->HasStandardMemoryLayout())
  {
    for (vtkIdType i = 0; i < array->GetNumberOfTuples(); ++i)
      for (int c = 0; c < array->GetNumberOfComponents(); ++c)
        if (!std::isfinite(array->GetComponent(i, c)))
          return "Array '" + std::string(array->GetName() ? array->GetName() : "") +
            "' has NaN or infinite values (the first at point " + std::to_string(i) +
            "): replace them (e.g. with the Calculator or Threshold filters) first.";
    return {};
  }
  // Every component: each point's values, read in place as one long line of voxels.
  view.data = array->GetVoidPointer(0);
  view.dims = { array->GetNumberOfTuples() * array->GetNumberOfComponents(), 1, 1 };
  const vao::ValueScan scan = vao::scanValues(view);
  if (scan.nonFiniteCount == 0)
  {
    return {};
  }
  std::ostringstream why;
  why << "Array '" << (array->GetName() ? array->GetName() : "") << "' has " << scan.nonFiniteCount
      << " NaN or infinite values (the first at point "
      << scan.firstNonFinite / array->GetNumberOfComponents()
      << "): they have no colour, opacity or shade; replace them (e.g. with the Calculator or "
         "Threshold "
         "filters) first.";
  return why.str();
}

std::string KernelError(
  const vao::Status& status, const ScalarVolume& scalars, const std::string& failed)
{
  if (status.ok || status.aborted)
  {
    return {};
  }
  if (status.outOfMemory)
  {
    // Said like the filters' own allocation failures (vtkAmbientOcclusionMemory). The
    // kernel names what it could not allocate, unless even that message could not be had
    // (Status::noMemory's short "out of memory").
    const std::string named = "not enough memory for ";
    const std::string what = status.message.compare(0, named.size(), named) == 0
      ? status.message.substr(named.size())
      : std::string("its working buffers");
    return "Not enough memory for " + what +
      "; compute it in smaller pieces (streaming or more MPI ranks), on a smaller extent, or with "
      "lighter settings (StartAtHalfResolution, fewer outputs).";
  }
  if (status.nonFiniteCount <= 0)
  {
    return failed + ": " + status.message + ".";
  }
  const vao::Index3& dims = scalars.view.dims;
  const std::int64_t first = status.firstNonFinite;
  const std::int64_t plane = dims[0] * dims[1];
  std::ostringstream why;
  why
    << "Array '" << scalars.name << "' has " << status.nonFiniteCount
    << " NaN or infinite values (the first at voxel " << first % dims[0] + scalars.firstVoxel[0]
    << ", " << (first / dims[0]) % dims[1] + scalars.firstVoxel[1] << ", "
    << first / plane + scalars.firstVoxel[2]
    << "). A non-finite value has no place in a cumulative distribution or an isosurface: replace "
       "them (e.g. with the Calculator or Threshold filters) first.";
  return why.str();
}

} // namespace vtkAmbientOcclusionArrayInput
