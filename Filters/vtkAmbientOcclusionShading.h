/**
 * @class   vtkAmbientOcclusionShading
 * @brief   Colours a volume or a surface with its ambient occlusion (Ruiz et al. Eq. 5).
 *
 * On image data: a 4-component unsigned char point array "ShadedRGBA" with
 * RGB = k * O * C_TF(v) (AmbientIntensity k, O the AO array raised to 1/Gamma, C_TF the
 * colour transfer function at the voxel's value) and A = alpha_TF(v), times
 * min(s2 / VarianceMax, 1) when ModulateOpacity is on (the intensity variance s2 from the
 * "Variance" array). Render it as a volume with dependent components (ParaView: Map
 * Scalars off) to see the AO without any other lighting.
 *
 * On a surface (any other data set): a 3-component unsigned char "ShadedRGB", the
 * colour map of its scalars (or white without scalars) times AO, and times "Shadow" when
 * that array exists.
 *
 * The transfer functions: set them (SetColorTransferFunction, SetOpacityTransferFunction)
 * or let the filter build them from ColorPreset over ScalarRange (the data range when
 * ScalarRange is empty) and an opacity ramp from 0 at OpacityRamp[0] to 1 at
 * OpacityRamp[1] (by default the upper half of the range).
 *
 * Threads: the filter computes on its own pool of threads, NumberOfThreads of them (0,
 * the default: the cores this process may use; under MPI, its share of the node's cores).
 * VTK's SMP settings (vtkSMPTools, VTK_SMP_MAX_THREADS, VTK_SMP_BACKEND_IN_USE) do not
 * apply: the default SMP backend of Debian 12's VTK 9.2 and ParaView 5.11 is Sequential
 * (one thread), and the kernels the filter runs are a library that builds without VTK.
 */
#ifndef vtkAmbientOcclusionShading_h
#define vtkAmbientOcclusionShading_h

#include "VolumetricAOFiltersModule.h" // for export macro
#include "vtkPassInputTypeAlgorithm.h"
#include "vtkSmartPointer.h"

#include <string>
#include <vector>

class vtkDataArray;
class vtkMultiProcessController;
class vtkPiecewiseFunction;
class vtkPointData;
class vtkScalarsToColors;
class vtkUnsignedCharArray;

class VOLUMETRICAOFILTERS_EXPORT vtkAmbientOcclusionShading : public vtkPassInputTypeAlgorithm
{
public:
  static vtkAmbientOcclusionShading* New();
  vtkTypeMacro(vtkAmbientOcclusionShading, vtkPassInputTypeAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  enum PresetType
  {
    GRAYSCALE = 0,
    BONE = 1,
    COOL_TO_WARM = 2
  };

  ///@{
  /// The AO array (default "AmbientOcclusion") and the scalars coloured (default: the
  /// active point scalars).
  vtkSetStdStringFromCharMacro(AmbientOcclusionArrayName);
  vtkGetCharFromStdStringMacro(AmbientOcclusionArrayName);
  vtkSetStdStringFromCharMacro(ScalarsArrayName);
  vtkGetCharFromStdStringMacro(ScalarsArrayName);
  /// ScalarsArrayName in the form of SetInputArrayToProcess (ParaView's `Scalars =
  /// ['POINTS', name]`); the association must be points.
  void SetScalarsArray(int idx, int port, int connection, int association, const char* name);
  ///@}

  ///@{
  /// k of Eq. 5 (default 1) and the gamma applied to the AO (default 1).
  vtkSetMacro(AmbientIntensity, double);
  vtkGetMacro(AmbientIntensity, double);
  vtkSetMacro(Gamma, double);
  vtkGetMacro(Gamma, double);
  ///@}

  ///@{
  /// Modulate the opacity by min(s2 / VarianceMax, 1) (default off). VarianceMax <= 0
  /// (default) picks (range / 20)^2 of the scalars: variances of a twentieth of the range
  /// count as a boundary.
  vtkSetMacro(ModulateOpacity, vtkTypeBool);
  vtkGetMacro(ModulateOpacity, vtkTypeBool);
  vtkBooleanMacro(ModulateOpacity, vtkTypeBool);
  vtkSetMacro(VarianceMax, double);
  vtkGetMacro(VarianceMax, double);
  ///@}

  ///@{
  /// The built-in transfer functions: colour preset over ScalarRange (empty, i.e.
  /// min > max, = the data range) and the opacity ramp.
  vtkSetMacro(ColorPreset, int);
  vtkGetMacro(ColorPreset, int);
  vtkSetVector2Macro(ScalarRange, double);
  vtkGetVector2Macro(ScalarRange, double);
  vtkSetVector2Macro(OpacityRamp, double);
  vtkGetVector2Macro(OpacityRamp, double);
  ///@}

  ///@{
  /// Explicit transfer functions (override the preset and the ramp when set).
  void SetColorTransferFunction(vtkScalarsToColors* colors);
  void SetOpacityTransferFunction(vtkPiecewiseFunction* opacity);
  ///@}

  ///@{
  /// The processes of a distributed run (default: the global controller): the automatic
  /// ScalarRange is the range over all of them, so every piece is coloured alike. Every
  /// process must execute the filter; nullptr: each piece's own range.
  ///@{
  /// Threads of this process (0, the default: the cores it may use, divided by the MPI
  /// ranks on its node). Negative values are an error.
  vtkSetMacro(NumberOfThreads, int);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

  void SetController(vtkMultiProcessController* controller);
  vtkMultiProcessController* GetController() const;
  ///@}

protected:
  vtkAmbientOcclusionShading();
  ~vtkAmbientOcclusionShading() override;

  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  vtkMTimeType GetMTime() override;

  std::string AmbientOcclusionArrayName = "AmbientOcclusion";
  std::string ScalarsArrayName;
  double AmbientIntensity = 1.0;
  double Gamma = 1.0;
  int NumberOfThreads = 0;
  vtkTypeBool ModulateOpacity = false;
  double VarianceMax = 0.0;
  int ColorPreset = GRAYSCALE;
  double ScalarRange[2] = { 1.0, 0.0 };
  double OpacityRamp[2] = { 1.0, 0.0 };
  vtkSmartPointer<vtkScalarsToColors> Colors;
  vtkSmartPointer<vtkPiecewiseFunction> Opacity;
  vtkSmartPointer<vtkMultiProcessController> Controller;

private:
  vtkAmbientOcclusionShading(const vtkAmbientOcclusionShading&) = delete;
  void operator=(const vtkAmbientOcclusionShading&) = delete;

  /// The input with its shaded colours (RequestData's body, inside its memory guard).
  int ProduceOutput(vtkInformationVector** inputVector, vtkInformationVector* outputVector);

  /// Why the parameters or the input's arrays cannot be shaded; empty when they can.
  std::string CheckInput(
    vtkPointData* pd, vtkIdType points, vtkDataArray* scalars, bool volume) const;
  /// ScalarRange, or when it is empty the range of the scalars (of each piece here) over
  /// every process. Collective.
  void ColourRange(const std::vector<vtkDataArray*>& scalars, double range[2]);
  /// Fills `shaded` (3 components a point, 4 on a volume); false when the user aborted.
  bool ShadePoints(vtkPointData* pd, vtkDataArray* scalars, bool volume, const double range[2],
    vtkUnsignedCharArray* shaded);
};

#endif
