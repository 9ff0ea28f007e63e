/**
 * @class   vtkProbeOutsideSurface
 * @brief   Samples a volume's point arrays just outside a surface, onto the surface.
 *
 * Input 0: a surface with point normals (e.g. Contour of a volume). Input 1: the volume,
 * typically the output of vtkOcclusionSweeping. Every point array of the volume is sampled
 * (trilinearly, by vtkProbeFilter) at p + d n, d = Distance times the volume's smallest
 * spacing, and added to the surface's points under its own name (replacing a surface array
 * of the same name).
 *
 * Why outside: the sweeping's AmbientOcclusion is 0 inside the occluder by definition, so
 * the field interpolated onto the isosurface itself mixes inside and outside voxels and
 * shows dark rings where the surface crosses voxel layers. Sampled a voxel and a half out,
 * it is the light that reaches the surface.
 *
 * Which way is out: with Orientation AUTO and a one-component "SignedDistance" array on
 * the volume (positive outside, as vtkOcclusionSweeping writes it), the filter samples it
 * on both sides of every point and takes the side where it is larger for most points (a
 * contour's normals all point the same way relative to the surface). Without it, AUTO
 * takes the normals as they are; NORMALS and REVERSED_NORMALS fix the choice. A point
 * whose sample would leave the volume, or whose normal is zero, is sampled on the surface.
 *
 * Under MPI each process asks for its piece of the volume grown by the distance plus two
 * voxels; as with Isosurface Ambient Occlusion, feed the volume from its own reader or
 * filter output when the surface is contoured from a distributed volume.
 */
#ifndef vtkProbeOutsideSurface_h
#define vtkProbeOutsideSurface_h

#include "VolumetricAOFiltersModule.h" // for export macro
#include "vtkPolyDataAlgorithm.h"

#include <string> // for InputError

class vtkAlgorithmOutput;
class vtkDataArray;
class vtkImageData;
class vtkPolyData;

class VOLUMETRICAOFILTERS_EXPORT vtkProbeOutsideSurface : public vtkPolyDataAlgorithm
{
public:
  static vtkProbeOutsideSurface* New();
  vtkTypeMacro(vtkProbeOutsideSurface, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum OrientationType
  {
    AUTO = 0,
    NORMALS = 1,
    REVERSED_NORMALS = 2
  };

  ///@{
  /// Distance of the samples from the surface, in units of the volume's smallest spacing
  /// (default 1.5; 0 samples on the surface itself).
  vtkSetMacro(Distance, double);
  vtkGetMacro(Distance, double);
  ///@}

  ///@{
  /// Which side of the surface is outside (default AUTO: by the volume's SignedDistance).
  vtkSetMacro(Orientation, int);
  vtkGetMacro(Orientation, int);
  ///@}

  /// The volume (input port 1).
  void SetVolumeConnection(vtkAlgorithmOutput* volume) { this->SetInputConnection(1, volume); }

  /// +1 when the last update sampled along the normals, -1 against them.
  vtkGetMacro(LastSide, int);

protected:
  vtkProbeOutsideSurface();
  ~vtkProbeOutsideSurface() override = default;

  vtkTypeBool ProcessRequest(
    vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int FillInputPortInformation(int port, vtkInformation* info) override;
  /// Voxels of the volume a piece's points reach, per axis (Distance and two voxels).
  void ReachOf(const double spacing[3], int reach[3]) const;
  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

private:
  vtkProbeOutsideSurface(const vtkProbeOutsideSurface&) = delete;
  void operator=(const vtkProbeOutsideSurface&) = delete;

  /// The reason the inputs or parameters cannot be used, or an empty string.
  std::string InputError(vtkPolyData* surface, vtkImageData* volume) const;
  /// +1 or -1: the side of the normals that is outside (see the class documentation).
  int OutsideSide(
    vtkPolyData* surface, vtkDataArray* normals, vtkImageData* volume, double offset) const;
  /// RequestData's body, inside its memory guard: the volume each process needs, fetched
  /// under MPI, then ProduceOutput below.
  int ProduceOutput(vtkInformationVector** inputVector, vtkInformationVector* outputVector);
  /// The surface with the volume's arrays sampled outside it (the inputs were checked).
  int ProduceOutput(vtkPolyData* surface, vtkImageData* volume, vtkPolyData* output);

  double Distance = 1.5;
  int Orientation = AUTO;
  int LastSide = 1;
};

#endif
