#include "vtkAmbientOcclusionPhantom.h"

#include "vtkAmbientOcclusionMemory.h"
#include "vtkAmbientOcclusionRequest.h"

#include "vtkDataObject.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPointData.h"
#include "vtkShortArray.h"
#include "vtkStreamingDemandDrivenPipeline.h"

#include <algorithm>
#include <cmath>
#include <cstdint>

vtkStandardNewMacro(vtkAmbientOcclusionPhantom);

namespace
{

constexpr double FieldOfViewMm = 240.0;

/// Normalised ellipsoid distance: < 1 inside the ellipsoid of centre c and semi-axes a.
double Ellipsoid(
  double x, double y, double z, double cx, double cy, double cz, double ax, double ay, double az)
{
  const double u = (x - cx) / ax, v = (y - cy) / ay, w = (z - cz) / az;
  return u * u + v * v + w * w;
}

/// The mean density over the voxel's cell, from 3 x 3 x 3 samples: the partial volume
/// effect of a real scanner. Point samples would give every boundary a staircase, which
/// isosurfaces show as terraces and the AO of boundary voxels as moire rings.
double PartialVolume(double x, double y, double z, const double spacing[3])
{
  double sum = 0.0;
  for (int c = -1; c <= 1; ++c)
    for (int b = -1; b <= 1; ++b)
      for (int a = -1; a <= 1; ++a)
        sum += vtkAmbientOcclusionPhantom::Density(
          x + a * spacing[0] / 3.0, y + b * spacing[1] / 3.0, z + c * spacing[2] / 3.0);
  return sum / 27.0;
}

/// Deterministic noise in [-1, 1] from a voxel index (splitmix64).
double HashNoise(std::uint64_t index, std::uint64_t seed)
{
  std::uint64_t h = index + 0x9E3779B97F4A7C15ull * (seed + 1);
  h = (h ^ (h >> 30)) * 0xBF58476D1CE4E5B9ull;
  h = (h ^ (h >> 27)) * 0x94D049BB133111EBull;
  h ^= h >> 31;
  return static_cast<double>(h >> 11) / static_cast<double>(1ull << 53) * 2.0 - 1.0;
}

/// Smooth noise in [-1, 1]: hash values on a lattice of kNoiseCell voxels, trilinearly
/// interpolated. Acquired CT noise is correlated over a few voxels; white noise would make
/// every flat region's voxel-value AO a random rank (salt and pepper).
double SmoothNoise(int i, int j, int k, std::uint64_t seed)
{
  constexpr int kNoiseCell = 4;
  constexpr std::uint64_t kLattice = 1u << 20; // lattice indices stay below this
  const int c[3] = { i / kNoiseCell, j / kNoiseCell, k / kNoiseCell };
  const double f[3] = { (i % kNoiseCell) / double(kNoiseCell),
    (j % kNoiseCell) / double(kNoiseCell), (k % kNoiseCell) / double(kNoiseCell) };
  double sum = 0.0;
  for (int corner = 0; corner < 8; ++corner)
  {
    double weight = 1.0;
    std::uint64_t index = 0;
    for (int a = 2; a >= 0; --a)
    {
      const int bit = (corner >> a) & 1;
      weight *= bit ? f[a] : 1.0 - f[a];
      index = index * kLattice + static_cast<std::uint64_t>(c[a] + bit);
    }
    sum += weight * HashNoise(index, seed);
  }
  return sum;
}

} // namespace

//------------------------------------------------------------------------------
vtkAmbientOcclusionPhantom::vtkAmbientOcclusionPhantom()
{
  this->SetNumberOfInputPorts(0);
}

//------------------------------------------------------------------------------
double vtkAmbientOcclusionPhantom::Density(double x, double y, double z)
{
  // Axes: x left-right, y front(-)/back(+), z foot(-)/head(+); millimetres.
  const double air = -1000.0;
  // Headrest: a plate under the back of the head.
  if (y > 92.0 && y < 100.0 && std::abs(x) < 90.0 && z > -115.0 && z < 40.0)
  {
    return 250.0;
  }
  // Neck: an elliptic cylinder from the bottom to the skull base.
  const bool inNeck =
    z < -40.0 && ((x / 50.0) * (x / 50.0) + ((y - 10.0) / 45.0) * ((y - 10.0) / 45.0)) < 1.0;
  const double head = Ellipsoid(x, y, z, 0.0, 0.0, 10.0, 78.0, 95.0, 100.0);
  if (head >= 1.0 && !inNeck)
  {
    return air;
  }
  if (inNeck && head >= 1.0)
  {
    // Cervical spine inside the neck.
    const double spine = ((x / 12.0) * (x / 12.0) + ((y - 25.0) / 12.0) * ((y - 25.0) / 12.0));
    return spine < 1.0 ? 650.0 : 35.0;
  }
  // Air cavities: nasal cavity and a sinus behind it.
  if (Ellipsoid(x, y, z, 0.0, -70.0, -5.0, 10.0, 18.0, 22.0) < 1.0 ||
    Ellipsoid(x, y, z, 0.0, -55.0, 20.0, 22.0, 10.0, 10.0) < 1.0)
  {
    return air;
  }
  // Eyes: soft tissue globes in sockets cut through the skull.
  for (double side : { -32.0, 32.0 })
  {
    if (Ellipsoid(x, y, z, side, -75.0, 25.0, 16.0, 16.0, 15.0) < 1.0)
    {
      return 15.0;
    }
  }
  // Teeth: an arc of dense bone in the lower face.
  const double archRadius = std::sqrt(x * x + (y + 40.0) * (y + 40.0));
  if (y < -40.0 && std::abs(archRadius - 40.0) < 5.0 && z > -55.0 && z < -40.0)
  {
    return 1500.0;
  }
  // Skull: the shell between two ellipsoids, denser in its middle (diploe is lighter).
  const double outer = Ellipsoid(x, y, z, 0.0, 5.0, 22.0, 70.0, 86.0, 86.0);
  const double inner = Ellipsoid(x, y, z, 0.0, 5.0, 24.0, 63.0, 78.0, 78.0);
  if (outer < 1.0 && inner >= 1.0 && z > -35.0)
  {
    const double t = (outer - inner) / (1.0 - inner); // 0 at the inner surface, ~1 outside
    return 750.0 + 550.0 * std::abs(1.0 - 2.0 * t);
  }
  if (inner < 1.0 && z > -35.0)
  {
    // Brain with ventricles of CSF and a denser grey rim.
    for (double side : { -12.0, 12.0 })
    {
      if (Ellipsoid(x, y, z, side, 5.0, 35.0, 7.0, 28.0, 12.0) < 1.0)
      {
        return 5.0;
      }
    }
    return inner > 0.8 ? 42.0 : 30.0;
  }
  // Jaw bone below the skull base, in front of the neck.
  if (z > -75.0 && z < -35.0 && y < 0.0 &&
    Ellipsoid(x, y, z, 0.0, -30.0, -55.0, 55.0, 60.0, 22.0) < 1.0 &&
    Ellipsoid(x, y, z, 0.0, -30.0, -55.0, 47.0, 52.0, 16.0) >= 1.0)
  {
    return 900.0;
  }
  return 40.0; // skin, muscle, fat: soft tissue
}

//------------------------------------------------------------------------------
int vtkAmbientOcclusionPhantom::RequestInformation(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  for (int a = 0; a < 3; ++a)
  {
    if (this->Dimensions[a] < 2)
    {
      vtkErrorMacro(<< "Dimensions must be at least 2 on every axis (got " << this->Dimensions[0]
                    << " x " << this->Dimensions[1] << " x " << this->Dimensions[2] << ").");
      return 0;
    }
  }
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  const int whole[6] = { 0, this->Dimensions[0] - 1, 0, this->Dimensions[1] - 1, 0,
    this->Dimensions[2] - 1 };
  double spacing[3], origin[3];
  for (int a = 0; a < 3; ++a)
  {
    spacing[a] = FieldOfViewMm / this->Dimensions[a];
    origin[a] = -0.5 * spacing[a] * (this->Dimensions[a] - 1);
  }
  outInfo->Set(vtkStreamingDemandDrivenPipeline::WHOLE_EXTENT(), whole, 6);
  outInfo->Set(vtkDataObject::SPACING(), spacing, 3);
  outInfo->Set(vtkDataObject::ORIGIN(), origin, 3);
  vtkDataObject::SetPointDataActiveScalarInfo(outInfo, VTK_SHORT, 1);
  outInfo->Set(CAN_PRODUCE_SUB_EXTENT(), 1);
  return 1;
}

//------------------------------------------------------------------------------
int vtkAmbientOcclusionPhantom::RequestData(
  vtkInformation*, vtkInformationVector**, vtkInformationVector* outputVector)
{
  return vtkAmbientOcclusionRequest::ProduceOutput(this, outputVector, "choose smaller Dimensions.",
    [&] { return this->ProduceOutput(outputVector); });
}

//------------------------------------------------------------------------------
int vtkAmbientOcclusionPhantom::ProduceOutput(vtkInformationVector* outputVector)
{
  vtkInformation* outInfo = outputVector->GetInformationObject(0);
  vtkImageData* output = vtkImageData::GetData(outInfo);
  int ext[6];
  outInfo->Get(vtkStreamingDemandDrivenPipeline::UPDATE_EXTENT(), ext);
  double spacing[3], origin[3];
  outInfo->Get(vtkDataObject::SPACING(), spacing);
  outInfo->Get(vtkDataObject::ORIGIN(), origin);
  output->SetExtent(ext);
  output->SetSpacing(spacing);
  output->SetOrigin(origin);
  vtkNew<vtkShortArray> values;
  values->SetName("Density");
  vtkAmbientOcclusionMemory::Allocate(values, output->GetNumberOfPoints(), "the Density output");
  short* out = values->GetPointer(0);
  for (int k = ext[4]; k <= ext[5]; ++k)
  {
    this->UpdateProgress(static_cast<double>(k - ext[4]) / (ext[5] - ext[4] + 1));
    for (int j = ext[2]; j <= ext[3]; ++j)
    {
      for (int i = ext[0]; i <= ext[1]; ++i)
      {
        // Patient axes: image y runs front to back, image z foot to head.
        const double hu = PartialVolume(origin[0] + i * spacing[0], origin[1] + j * spacing[1],
          origin[2] + k * spacing[2], spacing);
        // Air stays clean, as in a CT whose air is clipped at the bottom of its range.
        const double noisy =
          hu <= -1000.0 ? hu : hu + this->NoiseAmplitude * SmoothNoise(i, j, k, this->Seed);
        *out++ = static_cast<short>(std::lround(std::max(-1024.0, std::min(3000.0, noisy))));
      }
    }
  }
  output->GetPointData()->SetScalars(values);
  return 1;
}

//------------------------------------------------------------------------------
void vtkAmbientOcclusionPhantom::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "Dimensions: " << this->Dimensions[0] << " x " << this->Dimensions[1] << " x "
     << this->Dimensions[2] << "\n";
  os << indent << "NoiseAmplitude: " << this->NoiseAmplitude << "\n";
  os << indent << "Seed: " << this->Seed << "\n";
}
