/**
 * @class   vtkIsosurfaceAmbientOcclusion
 * @brief   Ambient occlusion and soft shadows of an isosurface (Penner & Mitchell 2008).
 *
 * Input 0: a surface (e.g. the Contour filter's output) with point normals; without a
 * "Normals" array the normals are the volume's gradient at the points, oriented towards
 * lower values. Input 1: the volume. The volume's moments are blurred into a pyramid (see
 * vtkVarianceOcclusionMap) once; each surface point samples it at p + k r_l n on every
 * level l and bounds the occluded fraction with Chebyshev's (Cantelli's) inequality, or
 * estimates it with the Gaussian CDF of Ruiz et al.
 *
 * Outputs on the surface's points: float32 "AmbientOcclusion" (1 = open) and, with
 * ComputeShadows, "Shadow" (1 = lit) towards LightDirection.
 *
 * The pyramid is cached: changing only the surface, the query, the combination, the
 * estimator or the light re-samples it without rebuilding it (GetNumberOfPyramidBuilds()
 * counts the builds). It is keyed on the volume's array (pointer and MTime) and grid, so a
 * new shallow copy of the same volume (what ParaView passes on every update) reuses it;
 * after changing values in place, call Modified() on the array. The AmbientOcclusion is
 * kept too: moving the light only computes the shadows.
 *
 * On one process the pyramid's two finest levels (nearly all of its bytes) are kept only
 * where the surface samples them: each update builds the tiles of 8^3 voxels that its
 * points, their AO offsets and their shadow rays reach and keeps them for the next (a new
 * light reaches few more). The values are those of the whole pyramid, in a fraction of
 * its memory (build/bin/vao_memory; docs/performance.md). The volume's array
 * is read again when tiles are built. Under MPI each process keeps the whole levels of
 * its piece.
 *
 * Threads: the filter computes on its own pool of threads, NumberOfThreads of them (0,
 * the default: the cores this process may use; under MPI, its share of the node's cores).
 * VTK's SMP settings (vtkSMPTools, VTK_SMP_MAX_THREADS, VTK_SMP_BACKEND_IN_USE) do not
 * apply: the default SMP backend of Debian 12's VTK 9.2 and ParaView 5.11 is Sequential
 * (one thread), and the kernels the filter runs are a library that builds without VTK.
 */
#ifndef vtkIsosurfaceAmbientOcclusion_h
#define vtkIsosurfaceAmbientOcclusion_h

#include "VolumetricAOFiltersModule.h" // for export macro
#include "vtkPolyDataAlgorithm.h"
#include "vtkSmartPointer.h" // for the controller

#include <memory>
#include <vector>

class vtkDataArray;
class vtkMultiProcessController;
class vtkImageData;
namespace vao
{
struct PyramidParameters;
struct SurfaceOcclusionParameters;
}

class VOLUMETRICAOFILTERS_EXPORT vtkIsosurfaceAmbientOcclusion : public vtkPolyDataAlgorithm
{
public:
  static vtkIsosurfaceAmbientOcclusion* New();
  vtkTypeMacro(vtkIsosurfaceAmbientOcclusion, vtkPolyDataAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum QueryModeType
  {
    HALF_VOXEL_INSIDE = 0,
    ISO_VALUE = 1
  };
  enum CombineType
  {
    COMBINE_MAX = 0,
    COMBINE_MEAN = 1
  };
  enum EstimatorType
  {
    CHEBYSHEV = 0,
    GAUSSIAN_CDF = 1
  };

  /// The volume (input port 1).
  void SetVolumeConnection(vtkAlgorithmOutput* output) { this->SetInputConnection(1, output); }
  void SetVolumeData(vtkDataObject* volume) { this->SetInputData(1, volume); }

  /// The volume's point array (default: its active scalars); the same as
  /// SetInputArrayToProcess(0, 1, 0, FIELD_ASSOCIATION_POINTS, name).
  void SetVolumeScalars(const char* name);
  /// The same in the form of SetInputArrayToProcess (ParaView's `Scalars = ['POINTS',
  /// name]`): the index, port and connection are those of the volume's array whatever
  /// they say; the association must be points.
  void SetVolumeScalars(int idx, int port, int connection, int association, const char* name);

  ///@{
  /// Query value: the volume half a voxel inside the surface (default, the paper) or IsoValue.
  vtkSetMacro(QueryMode, int);
  vtkGetMacro(QueryMode, int);
  vtkSetMacro(IsoValue, double);
  vtkGetMacro(IsoValue, double);
  ///@}

  ///@{
  /// Pyramid levels (default 4) and their start at half resolution (default off).
  vtkSetMacro(NumberOfLevels, int);
  vtkGetMacro(NumberOfLevels, int);
  vtkSetMacro(StartAtHalfResolution, vtkTypeBool);
  vtkGetMacro(StartAtHalfResolution, vtkTypeBool);
  ///@}

  ///@{
  /// k: level l is sampled at p + k r_l n (default 1).
  vtkSetMacro(OffsetFactor, double);
  vtkGetMacro(OffsetFactor, double);
  ///@}

  ///@{
  /// Combination of the levels (COMBINE_MAX: the largest occlusion, default) and the
  /// estimator (CHEBYSHEV, default, or GAUSSIAN_CDF).
  vtkSetMacro(Combine, int);
  vtkGetMacro(Combine, int);
  vtkSetMacro(Estimator, int);
  vtkGetMacro(Estimator, int);
  ///@}

  ///@{
  /// Soft shadows towards LightDirection (default off; light from +z).
  vtkSetMacro(ComputeShadows, vtkTypeBool);
  vtkGetMacro(ComputeShadows, vtkTypeBool);
  vtkBooleanMacro(ComputeShadows, vtkTypeBool);
  vtkSetVector3Macro(LightDirection, double);
  vtkGetVector3Macro(LightDirection, double);
  ///@}

  ///@{
  /// Component of a multi-component volume array; -1 (default): single-component only.
  vtkSetMacro(Component, int);
  vtkGetMacro(Component, int);
  ///@}

  ///@{
  /// Threads of the pyramid's build and of the sampling on this process; 0 (default): the
  /// cores available to the process, divided among the MPI ranks on its node. Negative
  /// values are an error.
  vtkSetMacro(NumberOfThreads, int);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  /// How many times the pyramid was built (the cache's witness).
  int GetNumberOfPyramidBuilds() const { return this->PyramidBuilds; }

  ///@{
  /// The processes of a distributed run (default: the global controller). With more than
  /// one process and at least two levels, each process reads its piece of the volume (as
  /// ParaView splits it) grown by the reach of the finer levels' queries, builds those
  /// levels locally, and the coarsest level, which the soft shadows march through to the
  /// volume's border, is assembled from every process's piece and replicated. The surface
  /// must be the piece extracted from the same decomposition (e.g. Contour of the same
  /// reader). Every process must execute the filter. nullptr: each reads the whole volume.
  void SetController(vtkMultiProcessController* controller);
  vtkMultiProcessController* GetController() const;
  ///@}

protected:
  vtkIsosurfaceAmbientOcclusion();
  ~vtkIsosurfaceAmbientOcclusion() override;

  vtkTypeBool ProcessRequest(
    vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int FillInputPortInformation(int port, vtkInformation* info) override;
  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int QueryMode = HALF_VOXEL_INSIDE;
  double IsoValue = 0.0;
  int NumberOfLevels = 4;
  vtkTypeBool StartAtHalfResolution = false;
  double OffsetFactor = 1.0;
  int Combine = COMBINE_MAX;
  int Estimator = CHEBYSHEV;
  vtkTypeBool ComputeShadows = false;
  double LightDirection[3] = { 0.0, 0.0, 1.0 };
  int Component = -1;
  int NumberOfThreads = 0;
  int PyramidBuilds = 0;
  vtkSmartPointer<vtkMultiProcessController> Controller;

private:
  vtkIsosurfaceAmbientOcclusion(const vtkIsosurfaceAmbientOcclusion&) = delete;
  void operator=(const vtkIsosurfaceAmbientOcclusion&) = delete;

  /// The surface with its AmbientOcclusion (and Shadow) arrays (RequestData's body, inside
  /// its memory guard).
  int ProduceOutput(vtkInformationVector** inputVector, vtkInformationVector* outputVector);

  struct Cache;
  std::unique_ptr<Cache> Pyramid;

  bool CheckParameters();
  /// The kernel's parameters of the sampling, and of the pyramid (CheckParameters passed).
  vao::SurfaceOcclusionParameters Parameters() const;
  vao::PyramidParameters PyramidRequest() const;
  bool UpdatePyramid(vtkImageData* volume, vtkDataArray* chosen);
  bool IsDistributed() const;
  /// This process's piece of the volume as ParaView splits it.
  void PieceOf(const int whole[6], int piece[6]) const;
  /// The extent a piece's pyramid reads: the piece grown by the reach of the queries.
  void VolumeExtentOf(
    const int whole[6], const double spacing[3], const int piece[6], int ext[6]) const;
  /// Pieces handed over (a source that cannot be asked for an extent): when every
  /// process's surface lies in the piece it holds and the pieces fill the whole extent,
  /// `piece` becomes the held piece and `volume` that piece with its reach fetched from
  /// the neighbours (into `fetched`): 1. 0 when not (the whole volume is needed), -1 on
  /// an error (reported). Collective.
  int AdoptHeldPiece(vtkPolyData* surface, vtkImageData*& volume, const int whole[6], int piece[6],
    vtkImageData* fetched);
  /// The pyramid of this process's piece, its coarsest level replaced by the whole one.
  /// Collective: every process calls it, also after an error of its own.
  bool UpdateDistributedPyramid(
    vtkImageData* volume, vtkDataArray* chosen, const int whole[6], const int piece[6]);
  /// Replaces the coarsest level of this process's pyramid (built from `inputExt`) by the
  /// whole volume's, assembled from every process's piece. Collective.
  void ShareCoarsestLevel(
    vtkImageData* volume, const int whole[6], const int inputExt[6], const int piece[6]);
  /// Decides which frame the surface's points are in (the physical one, or the image's
  /// axes where the extracting filter ignored an oriented volume's direction matrix) and
  /// gives their bounds in the volume's own axis-aligned frame, where the kernels sample.
  void PlaceSurface(vtkPolyData* surface, double bounds[6]);
  /// The surface lies in the volume (or near this process's piece of it when distributed).
  bool CheckSurfaceInVolume(
    vtkPolyData* surface, vtkImageData* volume, const int whole[6], const int piece[6]);
  /// Samples the pyramid at the surface's points into output's AO (and Shadow) arrays.
  bool Shade(vtkPolyData* surface, vtkPolyData* output);
};

#endif
