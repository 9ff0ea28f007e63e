#include "vtkAmbientOcclusionArrayInput.h"

#include "vao/Validation.h"
#include "vao/VarianceOcclusionMap.h"

#include "vtkAlgorithm.h"
#include "vtkCellArray.h"
#include "vtkDataArray.h"
#include "vtkFloatArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"

#include <algorithm>
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

namespace
{

bool UsableNormal(const double* n)
{
  const double length2 = n[0] * n[0] + n[1] * n[1] + n[2] * n[2];
  return std::isfinite(length2) && length2 > 0.0;
}

/// The volume's gradient at p (image frame), turned towards lower values and made unit
/// length; false where it is zero.
bool GradientNormal(const ScalarVolume& volume, const std::array<double, 3>& origin,
  const std::array<double, 3>& spacing, const double* p, double* normal)
{
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
  if (!(length > 0.0) || !std::isfinite(length))
  {
    return false;
  }
  for (int a = 0; a < 3; ++a)
  {
    normal[a] = -g[a] / length;
  }
  return true;
}

/// For the points marked in `missing`, the area-weighted normal of the polygons around
/// them (image frame, from `points`), turned to agree with the usable normals of the
/// polygons' other points. A point with no polygon, or whose polygons have no area, keeps
/// its marker.
void FaceNormals(vtkPolyData* surface, const std::vector<double>& points,
  std::vector<double>& normals, std::vector<char>& missing)
{
  vtkCellArray* polys = surface->GetPolys();
  if (!polys || polys->GetNumberOfCells() == 0)
  {
    return;
  }
  const size_t n = missing.size();
  std::vector<double> face(3 * n, 0.0), around(3 * n, 0.0);
  vtkIdType count = 0;
  const vtkIdType* ids = nullptr;
  for (polys->InitTraversal(); polys->GetNextCell(count, ids);)
  {
    bool touches = false;
    for (vtkIdType k = 0; k < count && !touches; ++k)
      touches = missing[static_cast<size_t>(ids[k])] != 0;
    if (!touches)
      continue;
    double area[3] = { 0.0, 0.0, 0.0 }; // Newell's method: twice the area along the normal
    for (vtkIdType k = 0; k < count; ++k)
    {
      const double* a = &points[3 * static_cast<size_t>(ids[k])];
      const double* b = &points[3 * static_cast<size_t>(ids[(k + 1) % count])];
      area[0] += (a[1] - b[1]) * (a[2] + b[2]);
      area[1] += (a[2] - b[2]) * (a[0] + b[0]);
      area[2] += (a[0] - b[0]) * (a[1] + b[1]);
    }
    for (vtkIdType k = 0; k < count; ++k)
    {
      const size_t i = static_cast<size_t>(ids[k]);
      if (!missing[i])
        continue;
      for (vtkIdType m = 0; m < count; ++m)
      {
        const size_t j = static_cast<size_t>(ids[m]);
        for (int a = 0; a < 3 && !missing[j]; ++a)
          around[3 * i + a] += normals[3 * j + a];
      }
      for (int a = 0; a < 3; ++a)
        face[3 * i + a] += area[a];
    }
  }
  for (size_t i = 0; i < n; ++i)
  {
    double* f = &face[3 * i];
    const double* r = &around[3 * i];
    const double length = std::sqrt(f[0] * f[0] + f[1] * f[1] + f[2] * f[2]);
    if (!missing[i] || !(length > 0.0) || !std::isfinite(length))
      continue;
    const double sign = f[0] * r[0] + f[1] * r[1] + f[2] * r[2] < 0.0 ? -1.0 : 1.0;
    for (int a = 0; a < 3; ++a)
      normals[3 * i + a] = sign * f[a] / length;
    missing[i] = 0;
  }
}

bool AllUsable(vtkFloatArray* normals, vtkIdType count)
{
  const float* n = normals->GetPointer(0);
  for (vtkIdType i = 0; i < count; ++i)
  {
    const double v[3] = { n[3 * i], n[3 * i + 1], n[3 * i + 2] };
    if (!UsableNormal(v))
      return false;
  }
  return true;
}

}

bool SurfaceNormals(vtkPolyData* surface, const std::vector<double>& points,
  const vtkAmbientOcclusionFrame::Frame& frame, const ScalarVolume& volume,
  const std::array<double, 3>& origin, const std::array<double, 3>& spacing,
  std::vector<double>& normals, vtkIdType& replaced, std::string& error)
{
  const vtkIdType n = surface->GetNumberOfPoints();
  normals.resize(static_cast<size_t>(3 * n));
  std::vector<char> missing(static_cast<size_t>(n), 0);
  vtkDataArray* given = GivenNormals(surface);
  replaced = 0;
  for (vtkIdType i = 0; i < n; ++i)
  {
    double* normal = &normals[3 * i];
    if (given)
    {
      given->GetTuple(i, normal);
      if (UsableNormal(normal))
      {
        if (!frame.identity)
        {
          const std::array<double, 3> turned = frame.VectorToImage(normal);
          std::copy(turned.begin(), turned.end(), normal);
        }
        continue;
      }
      ++replaced;
    }
    if (!GradientNormal(volume, origin, spacing, &points[3 * i], normal))
    {
      missing[static_cast<size_t>(i)] = 1;
    }
  }
  // The gradient vanishes only at rare points of a contour (a saddle, a flat top): their
  // polygons still say which way the surface faces.
  if (std::find(missing.begin(), missing.end(), 1) != missing.end())
  {
    FaceNormals(surface, points, normals, missing);
  }
  const auto left = std::find(missing.begin(), missing.end(), 1);
  if (left != missing.end())
  {
    std::ostringstream why;
    why << "Point " << (left - missing.begin()) << " of the surface has "
        << (given ? "a zero or non-finite normal" : "no normal")
        << ", the volume's gradient is zero there and it has no polygon with an area: "
           "remove it (e.g. Clean), or give it a normal.";
    error = why.str();
    return false;
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
  // A zero or non-finite normal is replaced (SurfaceNormals): that takes the copy.
  out.inPlace = floatPoints && floatNormals && frame.identity && AllUsable(floatNormals, n);
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
  return SurfaceNormals(
    surface, out.points, frame, volume, origin, spacing, out.normals, out.replacedNormals, error);
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
