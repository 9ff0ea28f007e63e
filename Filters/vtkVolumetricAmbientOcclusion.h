/**
 * @class   vtkVolumetricAmbientOcclusion
 * @brief   Per-voxel ambient occlusion of a volume (Ruiz et al. 2010) as a point-data array.
 *
 * For every voxel x the filter estimates the openness O(x) = P(v <= q) over the box
 * neighbourhood of half-width Radius centred on x, clipped to the whole extent of the
 * data set: 1 = open, 0 = occluded (denser values occlude). q is the voxel's own value
 * (QueryMode = VoxelValue), IsoValue, or the voxel's value smoothed by a small Gaussian
 * (QueryMode = SmoothedValue, sigma QuerySmoothing voxels), which keeps CT noise from
 * turning even the exact AO into salt and pepper. The estimators:
 *  - Histogram CDF (default): the box's cumulative distribution at NumberOfBins thresholds
 *    taken from the whole data set's values, interpolated at q; O(1) per voxel and bin
 *    whatever the radius, within 0.001-0.014 RMS of Exact Box on the CT scans at 64 bins,
 *    and exact for data with at most NumberOfBins distinct values (uint8 with 256);
 *  - CDF Reconstruction, Gaussian CDF, Chebyshev: the papers' estimators from separable
 *    box statistics (mean, variance, minimum, maximum), O(1) per voxel;
 *  - Exact Box, Exact Sphere: brute-force counts, O(R^3) per voxel (references).
 *
 * Output: the input image with a float32 array OutputArrayName (default
 * "AmbientOcclusion") and, when ComputeVariance is on, a float32 array "Variance" (the
 * intensity variance of the box, for opacity modulation).
 *
 * Streaming and MPI: the filter asks its input for the requested extent grown by the
 * radius (and by the smoothed query's window, 3 QuerySmoothing voxels), clipped to the
 * whole extent, and produces exactly the requested extent, so any decomposition gives
 * the serial numbers. Histogram CDF's thresholds come from every voxel of the data set:
 * under MPI (Controller with several processes) each process summarises the voxels of
 * its piece and the summaries are reduced; in one process the filter reads the whole
 * extent (and still produces only the requested one).
 *
 * Errors (vtkErrorMacro, empty output): missing or non-numeric array, multi-component
 * array without a chosen Component, NaN or infinite voxels (they have no rank in a
 * cumulative distribution: replace them first), empty, 1-voxel or 2-D images, a radius
 * below one voxel on every axis, a negative or non-finite radius, a box that covers the
 * whole volume on every axis (every voxel would get the same neighbourhood).
 *
 * Threads: the filter computes on its own pool of threads, NumberOfThreads of them (0,
 * the default: the cores this process may use; under MPI, its share of the node's cores).
 * VTK's SMP settings (vtkSMPTools, VTK_SMP_MAX_THREADS, VTK_SMP_BACKEND_IN_USE) do not
 * apply: the default SMP backend of Debian 12's VTK 9.2 and ParaView 5.11 is Sequential
 * (one thread), and the kernels the filter runs are a library that builds without VTK.
 */
#ifndef vtkVolumetricAmbientOcclusion_h
#define vtkVolumetricAmbientOcclusion_h

#include "VolumetricAOFiltersModule.h" // for export macro
#include "vtkImageAlgorithm.h"

#include "vtkSmartPointer.h" // for the controller

#include <string>
#include <vector>

class vtkDataArray;
class vtkDoubleArray;
class vtkImageData;
class vtkMultiProcessController;
class vtkPiecewiseFunction;
namespace vao
{
struct AmbientOcclusionOutput;
struct AmbientOcclusionParameters;
struct RayParameters;
struct Region;
struct Status;
struct ValueScan;
struct VolumeView;
}

class VOLUMETRICAOFILTERS_EXPORT vtkVolumetricAmbientOcclusion : public vtkImageAlgorithm
{
public:
  static vtkVolumetricAmbientOcclusion* New();
  vtkTypeMacro(vtkVolumetricAmbientOcclusion, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  /// The kernel's methods (vao::Method: the .cxx checks that the values agree).
  enum MethodType
  {
    CDF_RECONSTRUCTION = 0,
    GAUSSIAN_CDF = 1,
    CHEBYSHEV = 2,
    EXACT_BOX = 3,
    EXACT_SPHERE = 4,
    HISTOGRAM_CDF = 5,
    TRANSFER_FUNCTION = 6,
    EXACT_RAYS = 7,
    RAYS = 8
  };
  enum RadiusUnitsType
  {
    VOXELS = 0,
    WORLD = 1
  };
  enum QueryModeType
  {
    VOXEL_VALUE = 0,
    ISO_VALUE = 1,
    SMOOTHED_VALUE = 2
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
  /// Estimator (default HISTOGRAM_CDF; before version 0.2 the default was GAUSSIAN_CDF).
  vtkSetMacro(Method, int);
  vtkGetMacro(Method, int);
  ///@}

  ///@{
  /// TRANSFER_FUNCTION: the opacity whose box mean occludes (openness = 1 - the mean
  /// opacity of the box); EXACT_RAYS: the opacity the rays pass through (openness = the
  /// mean transmittance of RayCount rays of length Radius); RAYS: the same openness,
  /// estimated from 26 cones at a cost that grows like log Radius. Evaluated as
  /// vtkPiecewiseFunction::GetValue does. In ParaView,
  /// the opacity transfer function of an array (GetOpacityTransferFunction): the filter's
  /// modification time includes the function's, so editing it re-executes the filter.
  void SetOpacityFunction(vtkPiecewiseFunction* opacity);
  vtkPiecewiseFunction* GetOpacityFunction() const;
  ///@}

  /// Includes the opacity function's modification time.
  vtkMTimeType GetMTime() override;

  ///@{
  /// EXACT_RAYS: the rays per voxel, along a Fibonacci sphere of directions (default 128,
  /// at most 65536).
  vtkSetMacro(RayCount, int);
  vtkGetMacro(RayCount, int);
  ///@}

  ///@{
  /// EXACT_RAYS and RAYS: the length, in world units, over which a voxel's opacity is the opacity
  /// function's value (a volume property's Scalar Opacity Unit Distance); 0 (default) for
  /// the smallest spacing.
  vtkSetMacro(OpacityUnitDistance, double);
  vtkGetMacro(OpacityUnitDistance, double);
  ///@}

  ///@{
  /// Radius of the box (the paper's kernel radius), in voxels or world units (default 10).
  vtkSetMacro(Radius, double);
  vtkGetMacro(Radius, double);
  vtkSetMacro(RadiusUnits, int);
  vtkGetMacro(RadiusUnits, int);
  ///@}

  ///@{
  /// Query value: the voxel's own value (default), IsoValue, or the smoothed value.
  vtkSetMacro(QueryMode, int);
  vtkGetMacro(QueryMode, int);
  vtkSetMacro(IsoValue, double);
  vtkGetMacro(IsoValue, double);
  ///@}

  ///@{
  /// Sigma of the smoothed query's Gaussian, in voxels on every axis (default 1; the
  /// window reaches ceil(3 sigma) voxels each side). In (0, 100].
  vtkSetMacro(QuerySmoothing, double);
  vtkGetMacro(QuerySmoothing, double);
  ///@}

  ///@{
  /// Histogram CDF: the number of thresholds, in [2, 1024] (default 64). More bins follow
  /// the exact result more closely and cost time in proportion.
  vtkSetMacro(NumberOfBins, int);
  vtkGetMacro(NumberOfBins, int);
  ///@}

  ///@{
  /// Histogram CDF: the ascending thresholds to use instead of the whole data set's
  /// (nullptr, the default: the filter computes them). With them set, the filter reads only
  /// the requested extent grown by the radius, also in one process, so it streams. Take
  /// them from ComputeHistogramThresholds, or from the field-data array
  /// "HistogramThresholds" that every Histogram CDF output carries.
  void SetHistogramThresholds(vtkDataArray* thresholds);
  vtkDataArray* GetHistogramThresholds() const;
  ///@}

  /// The thresholds Histogram CDF takes from the whole data set upstream of this filter
  /// (with NumberOfBins, the array to process and Component), read in `slabs` slabs along
  /// z, each an update of the upstream pipeline, so that a volume larger than memory is
  /// summarised slab by slab (the range first, then the histogram: the input is read
  /// twice). nullptr, with an error, on failure.
  vtkSmartPointer<vtkDoubleArray> ComputeHistogramThresholds(int slabs);

  ///@{
  /// The processes that share the data set, for Histogram CDF's thresholds (default: the
  /// global controller).
  void SetController(vtkMultiProcessController* controller);
  vtkMultiProcessController* GetController() const;
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
  /// Compute backend: AUTO (default: CUDA for every method with the voxel value or an iso
  /// value as the query, when a device is present and the extent has at least
  /// AutoCudaMinimumVoxels voxels, or whatever its size for Exact Box and Exact Sphere;
  /// else the CPU), CPU, or CUDA. Without a CUDA build or device, for the smoothed query,
  /// or when the device fails (e.g. out of memory), the CPU runs, with a warning when CUDA
  /// was asked for. The backend that ran ("CPU" or "CUDA") is reported by GetLastBackend() and in
  /// the output's field data string "AmbientOcclusionBackend".
  vtkSetMacro(Backend, int);
  vtkGetMacro(Backend, int);
  const char* GetLastBackend() const { return this->LastBackend.c_str(); }
  static constexpr long long AutoCudaMinimumVoxels = 1 << 20;
  ///@}

  ///@{
  /// The CUDA device among the visible ones (CUDA_VISIBLE_DEVICES applies first). Default
  /// -1: the process's rank on its node (from the MPI launcher) modulo the devices, so
  /// that the ranks of a multi-GPU node share them out. The device that ran is in the
  /// output's field data string "AmbientOcclusionDevice" ("CPU" when the CPU ran).
  vtkSetMacro(Device, int);
  vtkGetMacro(Device, int);
  const char* GetLastDevice() const { return this->LastDevice.c_str(); }
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

  /// Radius in voxels per axis for a given spacing (RadiusUnits applied); for EXACT_RAYS and
  /// RAYS, the voxels their results read along each axis (a ray of that radius, rounded up;
  /// Rays' cones a little more).
  void ComputeVoxelRadius(const double spacing[3], int radius[3]) const;

  /// True for the methods that read the opacity function (TRANSFER_FUNCTION, EXACT_RAYS,
  /// RAYS).
  bool UsesOpacityFunction() const;

  /// True for EXACT_RAYS and RAYS.
  bool CastsRays() const;

protected:
  vtkVolumetricAmbientOcclusion();
  ~vtkVolumetricAmbientOcclusion() override = default;

  vtkTypeBool ProcessRequest(
    vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int FillInputPortInformation(int port, vtkInformation* info) override;
  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int Method = HISTOGRAM_CDF;
  double Radius = 10.0;
  int RadiusUnits = VOXELS;
  int QueryMode = VOXEL_VALUE;
  double IsoValue = 0.0;
  double QuerySmoothing = 1.0;
  int NumberOfBins = 64;
  int RayCount = 128;
  double OpacityUnitDistance = 0.0;
  vtkSmartPointer<vtkMultiProcessController> Controller;
  vtkSmartPointer<vtkDataArray> HistogramThresholds;
  vtkSmartPointer<vtkPiecewiseFunction> OpacityFunction;
  int ErfApproximation = ERF_EXACT;
  vtkTypeBool ComputeVariance = false;
  int Component = -1;
  int Backend = BACKEND_AUTO;
  int Device = -1;
  int NumberOfThreads = 0;
  std::string OutputArrayName = "AmbientOcclusion";
  std::string LastBackend;
  std::string LastDevice;

private:
  vtkVolumetricAmbientOcclusion(const vtkVolumetricAmbientOcclusion&) = delete;
  void operator=(const vtkVolumetricAmbientOcclusion&) = delete;

  /// One RequestData's state, filled by its steps in turn (defined in the .cxx).
  struct Run;
  /// RequestData's body, inside its memory guard: the steps below in turn.
  int ProduceOutput(vtkInformationVector** inputVector, vtkInformationVector* outputVector);
  /// Checks this process's input against the request and reads its scalars (scanned for
  /// Histogram CDF's value range): false, with the error, when this process has nothing
  /// to compute (also an empty piece, which still takes part in the thresholds).
  bool ReadInput(vtkImageData* input, Run& run);
  /// Under MPI, the input this process needs (its piece grown by the reach) where the
  /// reader did not deliver it (a reader that does not split): fetched from the processes
  /// that hold it into `fetched`. Collective; nullptr, with the error, when nobody holds it.
  vtkImageData* NeededInput(vtkImageData* input, vtkInformationVector** inputVector,
    vtkInformationVector* outputVector, Run& run, vtkImageData* fetched);
  /// Runs the kernel on the requested extent into new output arrays, on the backend
  /// Compute chooses; false, with the kernel's error, when it fails.
  bool ComputeArrays(vtkImageData* input, Run& run);
  /// The output: the input's arrays cropped to the requested extent (the output is exactly
  /// that extent), the computed arrays, and the run's record (RecordRun).
  void AssembleOutput(vtkImageData* input, vtkImageData* output, const Run& run);
  /// The run in the output's field data, for the user and for later runs: Histogram CDF's
  /// thresholds (to reuse on other pieces), the backend and device that ran, the threads.
  void RecordRun(vtkImageData* output, const std::vector<double>& thresholds);

  bool CheckParameters();
  /// The kernel's parameters for a radius in voxels (CheckParameters passed).
  vao::AmbientOcclusionParameters Parameters(const int radius[3]) const;
  /// EXACT_RAYS and RAYS: the rays for voxels of this spacing (the identity direction matrix).
  vao::RayParameters Rays(const double spacing[3]) const;
  /// Half-widths in voxels of what a voxel's result reads: the radius, and the smoothed
  /// query's window when it is used.
  void ComputeReach(const double spacing[3], int reach[3]) const;
  /// Histogram CDF in a distributed run: the thresholds come from every process's piece.
  bool IsDistributed() const;
  /// Histogram CDF's thresholds for this run: the given ones, or the whole data set's
  /// (collective in a distributed run; see ProduceOutput).
  bool Thresholds(vtkImageData* input, const vao::VolumeView* volume, const vao::ValueScan& scan,
    const int outExt[6], const int whole[6], bool failed, std::vector<double>& thresholds);
  /// The input covers the requested extent `outExt`.
  bool CheckInputCovers(vtkImageData* input, const int outExt[6]);
  /// The radius in voxels for the input's spacing; false when it is 0 on every axis or
  /// covers the whole extent on every axis.
  bool CheckVoxelRadius(vtkImageData* input, const int whole[6], int radius[3]);
  /// Whether to run on the device: what runs on the CPU only (nullptr: nothing; else it
  /// names it, for the warning), the method is an exact reference (worth the transfers at
  /// any size), the extent's voxels.
  bool ChooseCuda(const char* cpuOnly, bool exactMethod, long long voxels);
  /// Runs the kernel on the chosen backend; a device failure falls back to the CPU.
  vao::Status Compute(const vao::VolumeView& volume, const vao::Region& region,
    const vao::AmbientOcclusionParameters& parameters, const vao::AmbientOcclusionOutput& arrays);
};

#endif
