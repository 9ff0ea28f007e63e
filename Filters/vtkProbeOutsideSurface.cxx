#include "vtkProbeOutsideSurface.h"

#include "vtkAmbientOcclusionArrayInput.h"
#include "vtkAmbientOcclusionCollectives.h"
#include "vtkAmbientOcclusionComposite.h"
#include "vtkAmbientOcclusionExtents.h"
#include "vtkAmbientOcclusionFrame.h"
#include "vtkAmbientOcclusionMemory.h"
#include "vtkAmbientOcclusionRequest.h"

#include "vtkDataArray.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkPoints.h"
#include "vtkPolyData.h"
#include "vtkProbeFilter.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <initializer_list>
#include <sstream>
#include <string>

vtkStandardNewMacro(vtkProbeOutsideSurface);

namespace Extents = vtkAmbientOcclusionExtents;

namespace
{
/// The array the sweeping writes, positive outside the occluder.
constexpr const char* kSignedDistance = "SignedDistance";

/// The smallest of three spacings, in world units.
double SmallestSpacing(const double h[3])
{
  return std::min({ std::abs(h[0]), std::abs(h[1]), std::abs(h[2]) });
}

/// Whether the physical point x lies in the volume's extent (its direction matrix applied).
bool InVolume(vtkImageData* volume, const double x[3])
{
  double index[3];
  volume->TransformPhysicalPointToContinuousIndex(x, index);
  const int* ext = volume->GetExtent();
  for (int a = 0; a < 3; ++a)
  {
    if (!(index[a] >= ext[2 * a] && index[a] <= ext[2 * a + 1]))
      return false;
  }
  return true;
}

/// p + offset n / |n| where that is in the volume and n is a usable normal; else p.
void Displaced(
  vtkImageData* volume, const double p[3], const double n[3], double offset, double x[3])
{
  const double length = std::sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  for (int a = 0; a < 3; ++a)
    x[a] = p[a];
  if (!(length > 0.0) || !std::isfinite(length))
    return;
  double moved[3];
  for (int a = 0; a < 3; ++a)
    moved[a] = p[a] + offset * n[a] / length;
  if (InVolume(volume, moved))
    std::copy(moved, moved + 3, x);
}

/// For every surface point, in turn, Displaced by each of `offsets`: the points to sample.
vtkSmartPointer<vtkPoints> DisplacedPoints(vtkPolyData* surface, vtkDataArray* normals,
  vtkImageData* volume, std::initializer_list<double> offsets)
{
  const vtkIdType n = surface->GetNumberOfPoints();
  const vtkIdType k = static_cast<vtkIdType>(offsets.size());
  auto points = vtkSmartPointer<vtkPoints>::New();
  points->SetDataTypeToDouble();
  vtkAmbientOcclusionMemory::Allocate(points->GetData(), k * n, "the points to sample");
  for (vtkIdType i = 0; i < n; ++i)
  {
    double p[3], normal[3], x[3];
    surface->GetPoint(i, p);
    normals->GetTuple(i, normal);
    vtkIdType j = k * i;
    for (double offset : offsets)
    {
      Displaced(volume, p, normal, offset, x);
      points->SetPoint(j++, x);
    }
  }
  return points;
}

/// vtkProbeFilter's samples of `volume`'s point arrays at `points`.
vtkSmartPointer<vtkDataSet> Sample(vtkImageData* volume, vtkPoints* points)
{
  // The probe allocates through VTK, which aborts where an allocation fails: make sure
  // first that its arrays (each of the volume's, the valid-point mask) fit.
  double bytesPerPoint = 1.0;
  vtkPointData* arrays = volume->GetPointData();
  for (int a = 0; a < arrays->GetNumberOfArrays(); ++a)
    if (vtkDataArray* array = arrays->GetArray(a))
      bytesPerPoint += array->GetNumberOfComponents() * array->GetDataTypeSize();
  vtkAmbientOcclusionMemory::Reserve(
    bytesPerPoint * points->GetNumberOfPoints(), "the samples of the volume's arrays");
  vtkNew<vtkPolyData> where;
  where->SetPoints(points);
  vtkNew<vtkProbeFilter> probe;
  probe->SetInputData(where);
  probe->SetSourceData(volume);
  probe->PassPointArraysOff();
  probe->PassCellArraysOff();
  probe->PassFieldArraysOff();
  probe->Update();
  return probe->GetOutput();
}
} // namespace

//------------------------------------------------------------------------------
vtkProbeOutsideSurface::vtkProbeOutsideSurface()
{
  this->SetNumberOfInputPorts(2);
}

//------------------------------------------------------------------------------
vtkTypeBool vtkProbeOutsideSurface::ProcessRequest(
  vtkInformation* request, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // The output is like the surface: polygonal data, or a composite data set of it.
  if (request->Has(vtkDemandDrivenPipeline::REQUEST_DATA_OBJECT()))
    return vtkAmbientOcclusionComposite::RequestDataObject(
      inputVector, outputVector, "vtkPolyData");
  return this->Superclass::ProcessRequest(request, inputVector, outputVector);
}

//------------------------------------------------------------------------------
int vtkProbeOutsideSurface::FillInputPortInformation(int port, vtkInformation* info)
{
  if (port == 0)
    vtkAmbientOcclusionComposite::AcceptSurfacesAndComposites(info);
  else
    vtkAmbientOcclusionComposite::AcceptImagesAndComposites(info);
  return 1;
}

//------------------------------------------------------------------------------
int vtkProbeOutsideSurface::FillOutputPortInformation(int, vtkInformation* info)
{
  info->Set(vtkDataObject::DATA_TYPE_NAME(), "vtkDataObject"); // made by ProcessRequest
  return 1;
}

//------------------------------------------------------------------------------
int vtkProbeOutsideSurface::RequestUpdateExtent(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  // One piece: the whole volume. Several: the piece of the surface's process, grown by
  // the distance and two voxels (a surface piece's ghost cells reach one voxel past it).
  vtkInformation* volumeInfo = inputVector[1]->GetInformationObject(0);
  if (vtkAmbientOcclusionComposite::IsComposite(volumeInfo))
    return 1; // the piece request passes on as it is; the pieces are gathered in RequestData
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  const int pieces = outInfo->Has(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES())
    ? outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES())
    : 1;
  if (pieces <= 1 || !std::isfinite(this->Distance))
  {
    Extents::RequestWholeExtent(volumeInfo);
    return 1;
  }
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  if (!Extents::CanProduceSubExtent(volumeInfo) &&
    vtkAmbientOcclusionRequest::Distributed(controller))
  {
    // A reader that does not split: read on one process, sent whole to the processes with
    // surface points (RequestData).
    Extents::RequestPieceOfWhole(
      volumeInfo, controller->GetLocalProcessId(), controller->GetNumberOfProcesses());
    return 1;
  }
  int whole[6], ext[6];
  double spacing[3] = { 1.0, 1.0, 1.0 };
  volumeInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
  if (volumeInfo->Has(vtkDataObject::SPACING()))
    volumeInfo->Get(vtkDataObject::SPACING(), spacing);
  Extents::RequestedPiece(outInfo, whole, ext);
  int reach[3];
  this->ReachOf(spacing, reach);
  Extents::GrowExtent(ext, reach, whole);
  Extents::RequestExactExtent(volumeInfo, ext);
  return 1;
}

//------------------------------------------------------------------------------
void vtkProbeOutsideSurface::ReachOf(const double spacing[3], int reach[3]) const
{
  // The distance and two voxels (a surface piece's ghost cells reach one voxel past it).
  const double smallest = SmallestSpacing(spacing);
  for (int a = 0; a < 3; ++a)
  {
    const double voxels =
      std::abs(spacing[a]) > 0.0 ? this->Distance * smallest / std::abs(spacing[a]) : 0.0;
    reach[a] = static_cast<int>(std::ceil(std::min(voxels, 1e6))) + 2;
  }
}

//------------------------------------------------------------------------------
std::string vtkProbeOutsideSurface::InputError(vtkPolyData* surface, vtkImageData* volume) const
{
  std::ostringstream why;
  if (!std::isfinite(this->Distance) || this->Distance < 0.0)
    why << "Distance must be a finite, non-negative number of voxels (got " << this->Distance
        << ").";
  else if (this->Orientation < AUTO || this->Orientation > REVERSED_NORMALS)
    why << "Unknown Orientation " << this->Orientation
        << " (0 Auto, 1 Normals, 2 Reversed Normals).";
  else if (surface->GetNumberOfPoints() == 0)
    return {}; // nothing to sample (a process without surface points under MPI)
  else if (!volume || volume->GetNumberOfPoints() == 0)
    why << "No volume: connect image data to the Volume input (e.g. the output of Occlusion "
           "Sweeping).";
  else if (volume->GetPointData()->GetNumberOfArrays() == 0)
    why << "The volume has no point arrays to sample.";
  else if (const double h = SmallestSpacing(volume->GetSpacing()); !(h > 0.0 && std::isfinite(h)))
    why << "The volume's spacing must be positive and finite.";
  else if (surface->GetNumberOfPoints() > 0 &&
    !vtkAmbientOcclusionArrayInput::GivenNormals(surface))
    why << "The surface has no point normals: turn on Compute Normals in Contour, or apply "
           "Generate Surface "
           "Normals first.";
  else if (vtkDataArray* normals = vtkAmbientOcclusionArrayInput::GivenNormals(surface))
  {
    if (normals->GetNumberOfTuples() != surface->GetNumberOfPoints())
      why << vtkAmbientOcclusionArrayInput::PointCountError(normals, surface->GetNumberOfPoints());
  }
  // The probe interpolates every array of the volume: one that does not fit its points
  // would be read past its end.
  vtkPointData* arrays = volume ? volume->GetPointData() : nullptr;
  for (int a = 0; why.str().empty() && arrays && a < arrays->GetNumberOfArrays(); ++a)
    why << vtkAmbientOcclusionArrayInput::PointCountError(
      arrays->GetArray(a), volume->GetNumberOfPoints());
  return why.str();
}

//------------------------------------------------------------------------------
int vtkProbeOutsideSurface::OutsideSide(
  vtkPolyData* surface, vtkDataArray* normals, vtkImageData* volume, double offset) const
{
  if (this->Orientation != AUTO)
    return this->Orientation == REVERSED_NORMALS ? -1 : 1;
  vtkDataArray* distance = volume->GetPointData()->GetArray(kSignedDistance);
  if (!distance || distance->GetNumberOfComponents() != 1 || !(offset > 0.0))
    return 1;
  // SignedDistance alone, on both sides of every point: a vote, since a contour's normals
  // all point the same way relative to its surface, while a point here and there (a thin
  // wall, the border) can see the other side as farther out.
  vtkNew<vtkImageData> field;
  field->CopyStructure(volume);
  field->GetPointData()->AddArray(distance);
  const vtkIdType n = surface->GetNumberOfPoints();
  vtkSmartPointer<vtkDataSet> samples =
    Sample(field, DisplacedPoints(surface, normals, volume, { offset, -offset }));
  vtkDataArray* sampled = samples->GetPointData()->GetArray(kSignedDistance);
  vtkIdType along = 0, against = 0;
  for (vtkIdType i = 0; sampled && i < n; ++i)
  {
    const double out = sampled->GetTuple1(2 * i), in = sampled->GetTuple1(2 * i + 1);
    along += out > in ? 1 : 0;
    against += in > out ? 1 : 0;
  }
  return against > along ? -1 : 1;
}

//------------------------------------------------------------------------------
int vtkProbeOutsideSurface::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  if (vtkAmbientOcclusionComposite::IsComposite(inputVector[0]->GetInformationObject(0)) ||
    vtkAmbientOcclusionComposite::IsComposite(inputVector[1]->GetInformationObject(0)))
    return vtkAmbientOcclusionComposite::ProduceOnSurface(this,
      vtkMultiProcessController::GetGlobalController(), inputVector, outputVector,
      [&](vtkInformationVector** in, vtkInformationVector* out)
      { return this->RequestData(nullptr, in, out); });
  return vtkAmbientOcclusionRequest::ProduceOutput(this, outputVector,
    "try a surface with fewer points (Decimate), or more MPI ranks.",
    [&] { return this->ProduceOutput(inputVector, outputVector); });
}

//------------------------------------------------------------------------------
int vtkProbeOutsideSurface::ProduceOutput(
  vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkPolyData* surface = vtkPolyData::GetData(inputVector[0], 0);
  vtkImageData* volume = vtkImageData::GetData(inputVector[1], 0);
  vtkPolyData* output = vtkPolyData::GetData(outputVector, 0);
  vtkNew<vtkImageData> fetched;
  vtkInformation* volumeInfo = inputVector[1]->GetInformationObject(0);
  vtkMultiProcessController* controller = vtkMultiProcessController::GetGlobalController();
  if (surface && volume && vtkAmbientOcclusionRequest::Distributed(controller) &&
    outputVector->GetInformationObject(0)->Get(
      vtkStreamingDemandDrivenPipeline::UPDATE_NUMBER_OF_PIECES()) > 1 &&
    std::isfinite(this->Distance) && !Extents::CanProduceSubExtent(volumeInfo))
  {
    // Pieces handed over, or a reader that does not split (collective, as
    // RequestUpdateExtent asked): when every process's surface lies in the piece it holds
    // (a Contour of it), each fetches its piece's reach from the neighbours; else every
    // process with surface points takes the whole volume from those that hold it.
    int whole[6], held[6] = { 0, -1, 0, -1, 0, -1 }, needed[6] = { 0, -1, 0, -1, 0, -1 };
    volumeInfo->Get(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole);
    if (volume->GetNumberOfPoints() > 0)
      volume->GetExtent(held);
    const bool hasPoints = surface->GetNumberOfPoints() > 0;
    const bool inside =
      !hasPoints || vtkAmbientOcclusionFrame::SurfaceWithinExtent(surface, volume, held, whole, 2);
    if (hasPoints)
      std::copy(whole, whole + 6, needed);
    if (vtkAmbientOcclusionCollectives::GlobalMax(controller, inside ? 0.0 : 1.0) == 0.0 &&
      hasPoints)
    {
      int reach[3];
      this->ReachOf(volume->GetSpacing(), reach);
      std::copy(held, held + 6, needed);
      Extents::GrowExtent(needed, reach, whole);
    }
    std::string why;
    volume = vtkAmbientOcclusionCollectives::CoverNeededExtent(
      controller, volume, whole, needed, fetched, why);
    if (!volume)
    {
      vtkErrorMacro(<< why);
      output->Initialize();
      return 1;
    }
  }
  const std::string error = this->InputError(surface, volume);
  if (!error.empty())
  {
    vtkErrorMacro(<< error);
    output->Initialize();
    return 1;
  }
  return this->ProduceOutput(surface, volume, output);
}

//------------------------------------------------------------------------------
int vtkProbeOutsideSurface::ProduceOutput(
  vtkPolyData* surface, vtkImageData* volume, vtkPolyData* output)
{
  output->ShallowCopy(surface);
  if (surface->GetNumberOfPoints() == 0)
    return 1;
  vtkDataArray* normals = vtkAmbientOcclusionArrayInput::GivenNormals(surface);
  const double offset = this->Distance * SmallestSpacing(volume->GetSpacing());
  this->LastSide = this->OutsideSide(surface, normals, volume, offset);
  this->UpdateProgress(0.4);
  if (this->GetAbortExecute())
  {
    output->Initialize();
    return 1;
  }
  vtkSmartPointer<vtkDataSet> samples =
    Sample(volume, DisplacedPoints(surface, normals, volume, { this->LastSide * offset }));
  this->UpdateProgress(0.9);

  // Every sampled array joins the surface's, under its own name; the probe's own mask
  // and the volume's ghost flags are not fields of the volume.
  vtkPointData* from = samples->GetPointData();
  for (int a = 0; a < from->GetNumberOfArrays(); ++a)
  {
    vtkDataArray* array = from->GetArray(a);
    const char* name = array ? array->GetName() : nullptr;
    if (!name || !strcmp(name, "vtkValidPointMask") ||
      !strcmp(name, vtkDataSetAttributes::GhostArrayName()))
      continue;
    output->GetPointData()->RemoveArray(name);
    output->GetPointData()->AddArray(array);
  }
  this->UpdateProgress(1.0);
  return 1;
}

//------------------------------------------------------------------------------
void vtkProbeOutsideSurface::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Distance: " << this->Distance << "\n";
  os << indent << "Orientation: " << this->Orientation << "\n";
  os << indent << "LastSide: " << this->LastSide << "\n";
}
