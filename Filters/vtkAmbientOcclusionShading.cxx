#include "vtkAmbientOcclusionShading.h"

#include "vtkAmbientOcclusionArrayInput.h"
#include "vtkAmbientOcclusionMemory.h"
#include "vtkAmbientOcclusionOpacity.h"
#include "vtkAmbientOcclusionRequest.h"

#include "vtkAmbientOcclusionCollectives.h"

#include "vao/AmbientOcclusion.h"
#include "vao/Shading.h"

#include "vtkColorTransferFunction.h"
#include "vtkCompositeDataIterator.h"
#include "vtkCompositeDataSet.h"
#include "vtkDataArray.h"
#include "vtkDataSet.h"
#include "vtkImageData.h"
#include "vtkInformation.h"
#include "vtkInformationVector.h"
#include "vtkMultiProcessController.h"
#include "vtkNew.h"
#include "vtkObjectFactory.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkUnsignedCharArray.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <vector>

vtkStandardNewMacro(vtkAmbientOcclusionShading);
vtkCxxSetSmartPointerMacro(vtkAmbientOcclusionShading, Controller, vtkMultiProcessController);

namespace
{

vtkSmartPointer<vtkScalarsToColors> PresetColors(int preset, const double range[2])
{
  auto colors = vtkSmartPointer<vtkColorTransferFunction>::New();
  const double lo = range[0], hi = range[1], mid = 0.5 * (lo + hi);
  switch (preset)
  {
    case vtkAmbientOcclusionShading::BONE:
      colors->AddRGBPoint(lo, 0.0, 0.0, 0.0);
      colors->AddRGBPoint(mid, 0.85, 0.78, 0.66);
      colors->AddRGBPoint(hi, 1.0, 1.0, 0.95);
      break;
    case vtkAmbientOcclusionShading::COOL_TO_WARM:
      colors->SetColorSpaceToDiverging();
      colors->AddRGBPoint(lo, 0.23, 0.30, 0.75);
      colors->AddRGBPoint(hi, 0.71, 0.02, 0.15);
      break;
    default:
      colors->AddRGBPoint(lo, 0.0, 0.0, 0.0);
      colors->AddRGBPoint(hi, 1.0, 1.0, 1.0);
  }
  return colors;
}

vtkSmartPointer<vtkPiecewiseFunction> RampOpacity(const double ramp[2])
{
  auto opacity = vtkSmartPointer<vtkPiecewiseFunction>::New();
  opacity->AddPoint(ramp[0], 0.0);
  opacity->AddPoint(ramp[1], 1.0);
  return opacity;
}

} // namespace

//------------------------------------------------------------------------------
vtkAmbientOcclusionShading::vtkAmbientOcclusionShading()
  : Controller(vtkMultiProcessController::GetGlobalController())
{
}

vtkAmbientOcclusionShading::~vtkAmbientOcclusionShading() = default;

vtkMultiProcessController* vtkAmbientOcclusionShading::GetController() const
{
  return this->Controller;
}

void vtkAmbientOcclusionShading::SetColorTransferFunction(vtkScalarsToColors* colors)
{
  this->Colors = colors;
  this->Modified();
}

void vtkAmbientOcclusionShading::SetOpacityTransferFunction(vtkPiecewiseFunction* opacity)
{
  this->Opacity = opacity;
  this->Modified();
}

vtkMTimeType vtkAmbientOcclusionShading::GetMTime()
{
  vtkMTimeType time = this->Superclass::GetMTime();
  time = this->Colors ? std::max(time, this->Colors->GetMTime()) : time;
  return this->Opacity ? std::max(time, this->Opacity->GetMTime()) : time;
}

//------------------------------------------------------------------------------
std::string vtkAmbientOcclusionShading::CheckInput(
  vtkPointData* pd, vtkIdType points, vtkDataArray* scalars, bool volume) const
{
  std::ostringstream why;
  vtkDataArray* ao = pd->GetArray(this->AmbientOcclusionArrayName.c_str());
  const std::string opacity = this->Opacity
    ? vtkAmbientOcclusionOpacity::Check(this->Opacity, "OpacityTransferFunction")
    : std::string();
  if (!std::isfinite(this->AmbientIntensity) || this->AmbientIntensity < 0.0)
    why << "AmbientIntensity must be a finite, non-negative number (got " << this->AmbientIntensity
        << ").";
  else if (!std::isfinite(this->Gamma) || !(this->Gamma > 0.0))
    why << "Gamma must be a finite, positive number (got " << this->Gamma << ").";
  else if (!std::isfinite(this->VarianceMax))
    why << "VarianceMax must be finite (0 or less: automatic).";
  else if (this->NumberOfThreads < 0)
    why << vtkAmbientOcclusionRequest::ThreadsError(this->NumberOfThreads);
  else if (this->ColorPreset < GRAYSCALE || this->ColorPreset > COOL_TO_WARM)
    why << "Unknown ColorPreset " << this->ColorPreset << " (0 Grayscale, 1 Bone, 2 Cool to Warm).";
  else if (!ao || ao->GetNumberOfComponents() != 1)
    why << "No one-component point array '" << this->AmbientOcclusionArrayName
        << "': apply an ambient occlusion filter first, or name its output array.";
  else if ((volume || !this->ScalarsArrayName.empty()) &&
    (!scalars || scalars->GetNumberOfComponents() != 1))
    why << "No one-component point scalars to colour"
        << (this->ScalarsArrayName.empty() ? "" : " named '") << this->ScalarsArrayName
        << (this->ScalarsArrayName.empty() ? "." : "'.");
  else if (volume && this->ModulateOpacity && !pd->GetArray("Variance"))
    why << "ModulateOpacity needs the point array 'Variance' (Volumetric Ambient Occlusion with "
           "Compute "
           "Variance on).";
  else if (!std::isfinite(this->ScalarRange[0]) || !std::isfinite(this->ScalarRange[1]))
    why << "ScalarRange must be finite (got " << this->ScalarRange[0] << ", "
        << this->ScalarRange[1] << "); an empty range such as (1, 0) means the data's.";
  else if (!std::isfinite(this->OpacityRamp[0]) || !std::isfinite(this->OpacityRamp[1]))
    why << "OpacityRamp must be finite (got " << this->OpacityRamp[0] << ", "
        << this->OpacityRamp[1]
        << "); an empty ramp such as (1, 0) means the upper half of the range.";
  else if (!opacity.empty())
    why << opacity;
  if (!why.str().empty())
    return why.str();
  // The arrays the colours come from, read a value a point: one short of the points would
  // be read past its end, and one non-finite value would turn the automatic range, and
  // with it every colour, into garbage.
  const bool shadowUsed = !volume;
  for (vtkDataArray* array : { scalars, ao, shadowUsed ? pd->GetArray("Shadow") : nullptr,
         volume && this->ModulateOpacity ? pd->GetArray("Variance") : nullptr })
  {
    std::string error = vtkAmbientOcclusionArrayInput::PointCountError(array, points);
    if (error.empty())
      error = vtkAmbientOcclusionArrayInput::NonFiniteError(array);
    if (!error.empty())
      return error;
  }
  return why.str();
}

//------------------------------------------------------------------------------
void vtkAmbientOcclusionShading::SetScalarsArray(int, int, int, int association, const char* name)
{
  if (association != vtkDataObject::FIELD_ASSOCIATION_POINTS)
  {
    vtkErrorMacro(<< "Scalars must be a point array (got association " << association << ").");
    return;
  }
  this->SetScalarsArrayName(name ? name : "");
}

//------------------------------------------------------------------------------
void vtkAmbientOcclusionShading::ColourRange(
  const std::vector<vtkDataArray*>& scalars, double range[2])
{
  range[0] = this->ScalarRange[0];
  range[1] = this->ScalarRange[1];
  if (range[0] > range[1])
  {
    // The data's range over every piece of every process.
    range[0] = std::numeric_limits<double>::infinity();
    range[1] = -range[0];
    for (vtkDataArray* array : scalars)
    {
      double own[2];
      if (array && array->GetNumberOfTuples() > 0)
      {
        array->GetRange(own, 0);
        range[0] = std::min(range[0], own[0]);
        range[1] = std::max(range[1], own[1]);
      }
    }
    vtkAmbientOcclusionCollectives::GlobalRange(this->Controller, range);
  }
}

//------------------------------------------------------------------------------
bool vtkAmbientOcclusionShading::ShadePoints(vtkPointData* pd, vtkDataArray* scalars, bool volume,
  const double range[2], vtkUnsignedCharArray* shaded)
{
  vtkDataArray* ao = pd->GetArray(this->AmbientOcclusionArrayName.c_str());
  vtkDataArray* shadow = volume ? nullptr : pd->GetArray("Shadow");
  vtkDataArray* variance = volume && this->ModulateOpacity ? pd->GetArray("Variance") : nullptr;
  vtkSmartPointer<vtkScalarsToColors> colors =
    this->Colors ? this->Colors : PresetColors(this->ColorPreset, range);
  double ramp[2] = { this->OpacityRamp[0], this->OpacityRamp[1] };
  if (ramp[0] > ramp[1])
  {
    ramp[0] = 0.5 * (range[0] + range[1]);
    ramp[1] = range[1];
  }
  vtkSmartPointer<vtkPiecewiseFunction> opacity = this->Opacity ? this->Opacity : RampOpacity(ramp);
  const double varianceMax =
    this->VarianceMax > 0.0 ? this->VarianceMax : std::pow((range[1] - range[0]) / 20.0, 2.0);
  const vtkIdType n = shaded->GetNumberOfTuples();
  const int components = volume ? 4 : 3;
  unsigned char* const pixels = shaded->GetPointer(0);
  // Points in chunks on the library's workers. Each chunk evaluates its own copies of the
  // transfer functions: their evaluation may build tables lazily, which is not
  // thread-safe on one shared object. Progress and abort are polled on this thread.
  const bool finished =
    vao::parallelRanges(n, vtkAmbientOcclusionRequest::Execution(this, this->NumberOfThreads),
      [&](std::int64_t begin, std::int64_t end)
      {
        vtkSmartPointer<vtkScalarsToColors> chunkColors =
          vtk::TakeSmartPointer(colors->NewInstance());
        chunkColors->DeepCopy(colors);
        vtkSmartPointer<vtkPiecewiseFunction> chunkOpacity =
          vtk::TakeSmartPointer(opacity->NewInstance());
        chunkOpacity->DeepCopy(opacity);
        unsigned char* out = pixels + begin * components;
        for (std::int64_t i = begin; i < end; ++i)
        {
          double rgb[3] = { 1.0, 1.0, 1.0 };
          const double v = scalars ? scalars->GetComponent(i, 0) : 0.0;
          if (scalars)
          {
            chunkColors->GetColor(v, rgb);
          }
          const double o = ao->GetComponent(i, 0) * (shadow ? shadow->GetComponent(i, 0) : 1.0);
          for (int c = 0; c < 3; ++c)
          {
            *out++ =
              vao::toByte(vao::ambientLighting(this->AmbientIntensity, o, rgb[c], this->Gamma));
          }
          if (volume)
          {
            const double m =
              variance ? vao::varianceModulation(variance->GetComponent(i, 0), varianceMax) : 1.0;
            *out++ = vao::toByte(chunkOpacity->GetValue(v) * m);
          }
        }
      });
  return finished;
}

//------------------------------------------------------------------------------
int vtkAmbientOcclusionShading::RequestData(
  vtkInformation*, vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  return vtkAmbientOcclusionRequest::ProduceOutput(this, outputVector,
    "shade a smaller extent or compute it in pieces (streaming or more MPI ranks).",
    [&] { return this->ProduceOutput(inputVector, outputVector); });
}

//------------------------------------------------------------------------------
int vtkAmbientOcclusionShading::ProduceOutput(
  vtkInformationVector** inputVector, vtkInformationVector* outputVector)
{
  vtkDataObject* input = vtkDataObject::GetData(inputVector[0]);
  vtkDataObject* output = vtkDataObject::GetData(outputVector);
  if (!input || !output)
  {
    return 1;
  }
  // The data sets to shade: the input, or each leaf of a composite input (coloured over
  // one range, so that every block looks alike).
  std::vector<vtkDataSet*> inputs;
  std::vector<vtkSmartPointer<vtkDataSet>> outputs;
  auto* composite = vtkCompositeDataSet::SafeDownCast(input);
  if (composite)
  {
    vtkCompositeDataSet::SafeDownCast(output)->CopyStructure(composite);
    for (vtkDataSet* leaf : vtkCompositeDataSet::GetDataSets<vtkDataSet>(composite))
    {
      inputs.push_back(leaf);
      outputs.push_back(vtk::TakeSmartPointer(leaf->NewInstance()));
    }
  }
  else if (auto* set = vtkDataSet::SafeDownCast(input))
  {
    inputs.push_back(set);
    outputs.push_back(vtkDataSet::SafeDownCast(output));
  }
  std::vector<vtkDataArray*> scalars;
  std::string error;
  for (vtkDataSet* set : inputs)
  {
    vtkPointData* pd = set->GetPointData();
    scalars.push_back(this->ScalarsArrayName.empty()
        ? pd->GetScalars()
        : pd->GetArray(this->ScalarsArrayName.c_str()));
    if (error.empty())
      error = this->CheckInput(
        pd, set->GetNumberOfPoints(), scalars.back(), vtkImageData::SafeDownCast(set) != nullptr);
  }
  // The range is reduced before any error return: every process must take part.
  double range[2];
  this->ColourRange(scalars, range);
  if (!error.empty())
  {
    vtkErrorMacro(<< error);
    output->Initialize();
    return 1;
  }
  for (size_t i = 0; i < inputs.size(); ++i)
  {
    outputs[i]->ShallowCopy(inputs[i]);
    const bool volume = vtkImageData::SafeDownCast(inputs[i]) != nullptr;
    vtkNew<vtkUnsignedCharArray> shaded;
    shaded->SetNumberOfComponents(volume ? 4 : 3);
    vtkAmbientOcclusionMemory::Allocate(
      shaded, inputs[i]->GetNumberOfPoints(), "the shaded colours");
    shaded->SetName(volume ? "ShadedRGBA" : "ShadedRGB");
    if (!this->ShadePoints(inputs[i]->GetPointData(), scalars[i], volume, range, shaded))
    {
      output->Initialize();
      return 1;
    }
    outputs[i]->GetPointData()->AddArray(shaded);
    outputs[i]->GetPointData()->SetActiveScalars(shaded->GetName());
  }
  if (composite)
  {
    // The leaves in GetDataSets' order: the same iteration sets them in place.
    vtkSmartPointer<vtkCompositeDataIterator> it = vtk::TakeSmartPointer(composite->NewIterator());
    size_t i = 0;
    for (it->InitTraversal(); !it->IsDoneWithTraversal() && i < outputs.size(); it->GoToNextItem())
      if (vtkDataSet::SafeDownCast(it->GetCurrentDataObject()) == inputs[i])
        vtkCompositeDataSet::SafeDownCast(output)->SetDataSet(it, outputs[i++]);
  }
  return 1;
}

//------------------------------------------------------------------------------
void vtkAmbientOcclusionShading::PrintSelf(ostream& os, vtkIndent indent)
{
  this->Superclass::PrintSelf(os, indent);
  os << indent << "AmbientOcclusionArrayName: " << this->AmbientOcclusionArrayName << "\n";
  os << indent << "ScalarsArrayName: " << this->ScalarsArrayName << "\n";
  os << indent << "AmbientIntensity: " << this->AmbientIntensity << ", Gamma: " << this->Gamma
     << "\n";
  os << indent << "ModulateOpacity: " << this->ModulateOpacity
     << ", VarianceMax: " << this->VarianceMax << "\n";
  os << indent << "ColorPreset: " << this->ColorPreset << ", ScalarRange: " << this->ScalarRange[0]
     << " " << this->ScalarRange[1] << ", OpacityRamp: " << this->OpacityRamp[0] << " "
     << this->OpacityRamp[1] << "\n";
  os << indent << "Controller: " << this->Controller.Get() << "\n";
}
