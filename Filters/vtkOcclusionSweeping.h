/**
 * @class   vtkOcclusionSweeping
 * @brief   Global ambient occlusion of an isosurface by occlusion sweeping (Singh et al. 2009).
 *
 * Builds the signed distance field of the isosurface v = IsoValue by fast sweeping and,
 * in the same eight sweeps, the visibility of the eight octants of the sky at every voxel
 * (Eq. 6 of the paper): light from an octant reaches a voxel through its three upwind
 * neighbours, attenuated by their transmittance (0 inside the surface, 1 outside, linear
 * across half a voxel). Unlike the box estimators this is global: an occluder anywhere
 * in the volume shadows everything behind it.
 *
 * Outputs (float32 point arrays): "SignedDistance" (world units, > 0 outside, < 0
 * inside), "AmbientOcclusion" (in [0, 1], 1 = open sky: the mean visibility of the
 * octants in OctantMask, or with UseGeometryTerm the cosine-weighted irradiance for the
 * surface normal, the gradient of the distance) and, with OutputOctantVisibility,
 * "OctantVisibility" (8 components in the order of the paper's Table 1).
 *
 * OctantMask selects the sky: all eight octants (skylight), the upper four (4..7, an
 * overcast sky), or one (a low-frequency shadow from that octant). Opacity < 1 makes the
 * occluders translucent. Sweeping is global: in one process the filter reads the whole
 * volume; under MPI each process sweeps a slab and the slabs exchange their faces until
 * they agree (see SetController).
 *
 * Threads: the filter computes on its own pool of threads, NumberOfThreads of them (0,
 * the default: the cores this process may use; under MPI, its share of the node's cores).
 * VTK's SMP settings (vtkSMPTools, VTK_SMP_MAX_THREADS, VTK_SMP_BACKEND_IN_USE) do not
 * apply: the default SMP backend of Debian 12's VTK 9.2 and ParaView 5.11 is Sequential
 * (one thread), and the kernels the filter runs are a library that builds without VTK.
 */
#ifndef vtkOcclusionSweeping_h
#define vtkOcclusionSweeping_h

#include "VolumetricAOFiltersModule.h" // for export macro
#include "vtkImageAlgorithm.h"
#include "vtkSmartPointer.h" // for the controller

#include <string>

class vtkDataArray;
class vtkMultiProcessController;
namespace vao
{
class BlockSweeper;
struct SweepParameters;
}

class VOLUMETRICAOFILTERS_EXPORT vtkOcclusionSweeping : public vtkImageAlgorithm
{
public:
  static vtkOcclusionSweeping* New();
  vtkTypeMacro(vtkOcclusionSweeping, vtkImageAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// The isosurface: values above IsoValue are inside (occlude) when InsideIsAbove is on
  /// (default), values below it otherwise.
  vtkSetMacro(IsoValue, double);
  vtkGetMacro(IsoValue, double);
  vtkSetMacro(InsideIsAbove, vtkTypeBool);
  vtkGetMacro(InsideIsAbove, vtkTypeBool);
  vtkBooleanMacro(InsideIsAbove, vtkTypeBool);
  ///@}

  ///@{
  /// Passes of the eight sweeps (default 1, as the paper); with ConvergenceTolerance > 0
  /// the passes stop once the distance changes by less (world units).
  vtkSetMacro(NumberOfIterations, int);
  vtkGetMacro(NumberOfIterations, int);
  vtkSetMacro(ConvergenceTolerance, double);
  vtkGetMacro(ConvergenceTolerance, double);
  ///@}

  ///@{
  /// Weight the octants by the geometry term of the surface normal (default off: the
  /// mean visibility, the scalar field of the paper's Fig. 6).
  vtkSetMacro(UseGeometryTerm, vtkTypeBool);
  vtkGetMacro(UseGeometryTerm, vtkTypeBool);
  vtkBooleanMacro(UseGeometryTerm, vtkTypeBool);
  ///@}

  ///@{
  /// Octants of the sky that shed light (Table 1 order, 1 = on; default all). The
  /// eight-argument form is the one ParaView's property calls.
  vtkSetVectorMacro(OctantMask, int, 8);
  vtkGetVectorMacro(OctantMask, int, 8);
  void SetOctantMask(int s0, int s1, int s2, int s3, int s4, int s5, int s6, int s7)
  {
    const int mask[8] = { s0, s1, s2, s3, s4, s5, s6, s7 };
    this->SetOctantMask(mask);
  }
  ///@}

  ///@{
  /// A <- A^(1/Gamma) (default 1; the paper uses 2). Opacity of the occluders in [0, 1]
  /// (default 1; below 1 light passes through: translucency, section 4.2).
  vtkSetMacro(Gamma, double);
  vtkGetMacro(Gamma, double);
  vtkSetMacro(Opacity, double);
  vtkGetMacro(Opacity, double);
  ///@}

  ///@{
  /// Also output the 8-component "OctantVisibility" (default off).
  vtkSetMacro(OutputOctantVisibility, vtkTypeBool);
  vtkGetMacro(OutputOctantVisibility, vtkTypeBool);
  vtkBooleanMacro(OutputOctantVisibility, vtkTypeBool);
  ///@}

  ///@{
  /// Component of a multi-component input array; -1 (default): single-component only.
  vtkSetMacro(Component, int);
  vtkGetMacro(Component, int);
  ///@}

  ///@{
  /// Threads of the sweeps on this process; 0 (default): the cores available to the
  /// process, divided among the MPI ranks on its node. Negative values are an error.
  vtkSetMacro(NumberOfThreads, int);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  /// Passes run and the last pass's largest change, from the last execution.
  int GetLastNumberOfPasses() const { return this->LastPasses; }
  double GetLastChange() const { return this->LastChange; }

  ///@{
  /// The processes of a distributed run (default: the global controller). With more
  /// than one process each one sweeps a slab of the volume along its longest axis (its
  /// input: that slab and one ghost layer, never the whole volume); signed distance and
  /// octant visibility cross the slab faces in rounds of exchanges until no ghost value
  /// changes by more than the tolerance (ConvergenceTolerance, or 1e-3 of the smallest
  /// spacing when it is 0); then every process receives the requested extent from the
  /// slabs that hold it. The result is the converged sweeping, equal to a serial run
  /// that converges (NumberOfIterations large, ConvergenceTolerance > 0). Every process
  /// must execute the filter. nullptr: each process sweeps the whole volume.
  void SetController(vtkMultiProcessController* controller);
  vtkMultiProcessController* GetController() const;
  ///@}

  /// Rounds of face exchanges of the last distributed execution (0 when serial); also in
  /// the output's field data as "SweepingExchangeRounds".
  int GetLastNumberOfExchangeRounds() const { return this->LastRounds; }

protected:
  vtkOcclusionSweeping();
  ~vtkOcclusionSweeping() override;

  vtkTypeBool ProcessRequest(
    vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int FillInputPortInformation(int port, vtkInformation* info) override;
  int FillOutputPortInformation(int port, vtkInformation* info) override;
  int RequestInformation(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  double IsoValue = 0.0;
  vtkTypeBool InsideIsAbove = true;
  int NumberOfIterations = 1;
  double ConvergenceTolerance = 0.0;
  vtkTypeBool UseGeometryTerm = false;
  int OctantMask[8] = { 1, 1, 1, 1, 1, 1, 1, 1 };
  double Gamma = 1.0;
  double Opacity = 1.0;
  vtkTypeBool OutputOctantVisibility = false;
  int Component = -1;
  int NumberOfThreads = 0;
  int LastPasses = 0;
  double LastChange = 0.0;
  int LastRounds = 0;
  vtkSmartPointer<vtkMultiProcessController> Controller;

private:
  vao::SweepParameters Parameters() const;
  bool IsDistributed(const int whole[6]) const;
  void WarnNoSurface(const std::string& arrayName);
  /// The distributed execution (Controller with several processes).
  int RequestDistributedData(vtkImageData* input, vtkImageData* output, const int whole[6],
    const int outExt[6], vtkDataArray* chosen);
  /// This process's slab: its scalars and its block sweeper.
  struct Slab;
  /// Starts the block sweeper of this process's slab; the reason when it cannot.
  std::string StartSlab(vtkImageData* input, vtkDataArray* chosen, const int whole[6], Slab& slab);
  /// Rounds of sweeps and face exchanges over the slab's block until the ghosts settle
  /// on every process; -1 when the run was aborted or failed (the failure reported) on
  /// any process.
  int SweepRounds(Slab& slab, int axis, double tolerance);
  /// The error of a distributed run that stopped on every process: this process's
  /// `error`, or, empty, that another process failed.
  void ReportStop(const std::string& error);

  vtkOcclusionSweeping(const vtkOcclusionSweeping&) = delete;
  void operator=(const vtkOcclusionSweeping&) = delete;

  /// The swept distance and occlusion of the requested extent (RequestData's body, inside
  /// its memory guard).
  int ProduceOutput(vtkInformationVector** inputVector, vtkInformationVector* outputVector);
};

#endif
