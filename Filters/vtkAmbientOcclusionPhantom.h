/**
 * @class   vtkAmbientOcclusionPhantom
 * @brief   Generates a CT-like analytic head phantom (int16, Hounsfield units).
 *
 * The project's own default volume, for demos and for tests that must run anywhere:
 * air (-1000 HU) around a head of soft tissue (skin, brain ~ 20-45 HU) inside a skull of
 * bone (750-1300 HU) with eye sockets, a nasal cavity of air, ventricles of CSF (~5 HU),
 * teeth (~1500 HU), a neck and a headrest plate under it. Deterministic noise of
 * NoiseAmplitude HU, correlated over 4 voxels like acquired CT noise (a hash of the
 * voxel index and Seed, smoothly interpolated), makes the tissue look acquired; air stays
 * at -1000 HU.
 *
 * The phantom spans a fixed 240 mm field of view: Spacing = 240 mm / Dimensions, the
 * origin at the centre. RequestData fills only the requested extent, so the source
 * streams and splits across MPI ranks like a reader.
 */
#ifndef vtkAmbientOcclusionPhantom_h
#define vtkAmbientOcclusionPhantom_h

#include "VolumetricAOFiltersModule.h" // for export macro
#include "vtkImageAlgorithm.h"

class VOLUMETRICAOFILTERS_EXPORT vtkAmbientOcclusionPhantom : public vtkImageAlgorithm
{
public:
  static vtkAmbientOcclusionPhantom* New();
  vtkTypeMacro(vtkAmbientOcclusionPhantom, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Number of voxels per axis (default 128 x 128 x 128; each at least 2).
  vtkSetVector3Macro(Dimensions, int);
  vtkGetVector3Macro(Dimensions, int);
  ///@}

  ///@{
  /// Amplitude of the smooth noise (correlated over about 4 voxels) added to tissue and
  /// bone, in HU (default 20; 0 for a noiseless phantom).
  vtkSetMacro(NoiseAmplitude, double);
  vtkGetMacro(NoiseAmplitude, double);
  vtkSetMacro(Seed, int);
  vtkGetMacro(Seed, int);
  ///@}

  /// Hounsfield value of the noiseless phantom at a point (mm, origin at the centre).
  static double Density(double x, double y, double z);

protected:
  vtkAmbientOcclusionPhantom();
  ~vtkAmbientOcclusionPhantom() override = default;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Dimensions[3] = { 128, 128, 128 };
  double NoiseAmplitude = 20.0;
  int Seed = 1;

private:
  vtkAmbientOcclusionPhantom(const vtkAmbientOcclusionPhantom&) = delete;
  void operator=(const vtkAmbientOcclusionPhantom&) = delete;

  /// Fills the requested extent of the phantom (RequestData's body, inside its memory guard).
  int ProduceOutput(vtkInformationVector* outputVector);
};

#endif
