/**
 * @class   vtkVolumetricAmbientOcclusion
 * @brief   Per-voxel ambient occlusion of a volume (Ruiz et al. 2010) as a point-data array.
 *
 * For every voxel x the filter estimates the openness O(x) = P(v <= q) over the box
 * neighbourhood of half-width Radius centred on x, clipped to the whole extent of the
 * data set: 1 = open, 0 = occluded (denser values occlude). q is the voxel's own value
 * (QueryMode = VoxelValue) or IsoValue. The estimators:
 *  - CDF Reconstruction, Gaussian CDF, Chebyshev: from separable box statistics (mean,
 *    variance, minimum, maximum), O(1) per voxel whatever the radius;
 *  - Exact Box, Exact Sphere: brute-force counts, O(R^3) per voxel (references).
 *
 * Output: the input image with a float32 array OutputArrayName (default
 * "AmbientOcclusion") and, when ComputeVariance is on, a float32 array "Variance" (the
 * intensity variance of the box, for opacity modulation).
 *
 * Streaming and MPI: the filter asks its input for the requested extent grown by the
 * radius (clipped to the whole extent) and produces exactly the requested extent, so any
 * decomposition gives the serial numbers.
 *
 * Errors (vtkErrorMacro, empty output): missing or non-numeric array, multi-component
 * array without a chosen Component, NaN or infinite voxels (they have no rank in a
 * cumulative distribution: replace them first), empty, 1-voxel or 2-D images, a radius
 * below one voxel on every axis, a negative or non-finite radius, a box that covers the
 * whole volume on every axis (every voxel would get the same neighbourhood).
 */
#ifndef vtkVolumetricAmbientOcclusion_h
#define vtkVolumetricAmbientOcclusion_h

#include "VolumetricAOFiltersModule.h" // for export macro
#include "vtkImageAlgorithm.h"

#include <string>

class vtkImageData;
namespace vao
{
struct AmbientOcclusionOutput;
struct AmbientOcclusionParameters;
struct Region;
struct Status;
struct VolumeView;
}

class VOLUMETRICAOFILTERS_EXPORT vtkVolumetricAmbientOcclusion : public vtkImageAlgorithm
{
public:
  static vtkVolumetricAmbientOcclusion* New();
  vtkTypeMacro(vtkVolumetricAmbientOcclusion, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum MethodType
  {
    CDF_RECONSTRUCTION = 0,
    GAUSSIAN_CDF = 1,
    CHEBYSHEV = 2,
    EXACT_BOX = 3,
    EXACT_SPHERE = 4
  };
  enum RadiusUnitsType
  {
    VOXELS = 0,
    WORLD = 1
  };
  enum QueryModeType
  {
    VOXEL_VALUE = 0,
    ISO_VALUE = 1
  };
  enum ErfApproximationType
  {
    ERF_EXACT = 0,
    ERF_WINITZKI = 1
  };
  enum BackendType
  {
    BACKEND_AUTO = 0,
    BACKEND_CPU = 1,
    BACKEND_CUDA = 2
  };

  ///@{
  /// Estimator (default GAUSSIAN_CDF).
  vtkSetMacro(Method, int);
  vtkGetMacro(Method, int);
  ///@}

  ///@{
  /// Radius of the box (the paper's kernel radius), in voxels or world units (default 10).
  vtkSetMacro(Radius, double);
  vtkGetMacro(Radius, double);
  vtkSetMacro(RadiusUnits, int);
  vtkGetMacro(RadiusUnits, int);
  ///@}

  ///@{
  /// Query value: the voxel's own value (default) or IsoValue.
  vtkSetMacro(QueryMode, int);
  vtkGetMacro(QueryMode, int);
  vtkSetMacro(IsoValue, double);
  vtkGetMacro(IsoValue, double);
  ///@}

  ///@{
  /// erf of the Gaussian CDF: exact (default) or Winitzki's approximation.
  vtkSetMacro(ErfApproximation, int);
  vtkGetMacro(ErfApproximation, int);
  ///@}

  ///@{
  /// Also output the intensity variance of the box as "Variance" (default off).
  vtkSetMacro(ComputeVariance, vtkTypeBool);
  vtkGetMacro(ComputeVariance, vtkTypeBool);
  vtkBooleanMacro(ComputeVariance, vtkTypeBool);
  ///@}

  ///@{
  /// Component of a multi-component input array to process; -1 (default) accepts
  /// single-component arrays only.
  vtkSetMacro(Component, int);
  vtkGetMacro(Component, int);
  ///@}

  ///@{
  /// Compute backend: AUTO (default: CUDA for the separable methods when a device is
  /// present and the extent has at least AutoCudaMinimumVoxels voxels, else the CPU),
  /// CPU, or CUDA. Without a CUDA build or device, for the exact methods, or when the
  /// device fails (e.g. out of memory), the CPU runs, with a warning when CUDA was asked
  /// for. The backend that ran ("CPU" or "CUDA") is reported by GetLastBackend() and in
  /// the output's field data string "AmbientOcclusionBackend".
  vtkSetMacro(Backend, int);
  vtkGetMacro(Backend, int);
  const char* GetLastBackend() const { return this->LastBackend.c_str(); }
  static constexpr long long AutoCudaMinimumVoxels = 1 << 20;
  ///@}

  ///@{
  /// Threads of the CPU backend on this process; 0 (default): the cores available to the
  /// process, divided among the MPI ranks on its node. Negative values are an error.
  vtkSetMacro(NumberOfThreads, int);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  ///@{
  /// Name of the openness array (default "AmbientOcclusion").
  vtkSetStdStringFromCharMacro(OutputArrayName);
  vtkGetCharFromStdStringMacro(OutputArrayName);
  ///@}

  /// Radius in voxels per axis for a given spacing (RadiusUnits applied).
  void ComputeVoxelRadius(const double spacing[3], int radius[3]) const;

protected:
  vtkVolumetricAmbientOcclusion();
  ~vtkVolumetricAmbientOcclusion() override = default;

  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Method = GAUSSIAN_CDF;
  double Radius = 10.0;
  int RadiusUnits = VOXELS;
  int QueryMode = VOXEL_VALUE;
  double IsoValue = 0.0;
  int ErfApproximation = ERF_EXACT;
  vtkTypeBool ComputeVariance = false;
  int Component = -1;
  int Backend = BACKEND_AUTO;
  int NumberOfThreads = 0;
  std::string OutputArrayName = "AmbientOcclusion";
  std::string LastBackend;

private:
  vtkVolumetricAmbientOcclusion(const vtkVolumetricAmbientOcclusion&) = delete;
  void operator=(const vtkVolumetricAmbientOcclusion&) = delete;

  bool CheckParameters();
  /// The kernel's parameters for a radius in voxels (CheckParameters passed).
  vao::AmbientOcclusionParameters Parameters(const int radius[3]) const;
  /// The input covers the requested extent `outExt`.
  bool CheckInputCovers(vtkImageData* input, const int outExt[6]);
  /// The radius in voxels for the input's spacing; false when it is 0 on every axis or
  /// covers the whole extent on every axis.
  bool CheckVoxelRadius(vtkImageData* input, const int whole[6], int radius[3]);
  bool ChooseCuda(bool separableMethod, long long voxels);
  /// Runs the kernel on the chosen backend; a device failure falls back to the CPU.
  vao::Status Compute(const vao::VolumeView& volume, const vao::Region& region,
    const vao::AmbientOcclusionParameters& parameters, const vao::AmbientOcclusionOutput& arrays);
};

#endif
