// vtkVolumetricAmbientOcclusion: Histogram CDF's thresholds (given, computed from the whole
// data set, or read from a streamed input in slabs) and the distributed run's test.
#include "vtkVolumetricAmbientOcclusion.h"

#include "vtkAmbientOcclusionArrayInput.h"
#include "vtkAmbientOcclusionThresholds.h"

#include "vao/HistogramCdf.h"
#include "vao/Validation.h"

#include "vtkAlgorithmOutput.h"
#include "vtkDataArray.h"
#include "vtkDoubleArray.h"
#include "vtkImageData.h"
#include "vtkMultiProcessController.h"

#include <new>

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::IsDistributed() const
{
  return this->Method == HISTOGRAM_CDF && !this->HistogramThresholds && this->Controller &&
    this->Controller->GetNumberOfProcesses() > 1;
}

//------------------------------------------------------------------------------
void vtkVolumetricAmbientOcclusion::SetHistogramThresholds(vtkDataArray* thresholds)
{
  if (this->HistogramThresholds != thresholds)
  {
    this->HistogramThresholds = thresholds;
    this->Modified();
  }
}

//------------------------------------------------------------------------------
vtkDataArray* vtkVolumetricAmbientOcclusion::GetHistogramThresholds() const
{
  return this->HistogramThresholds;
}

//------------------------------------------------------------------------------
vtkSmartPointer<vtkDoubleArray> vtkVolumetricAmbientOcclusion::ComputeHistogramThresholds(int slabs)
{
  vtkAlgorithm* producer =
    this->GetNumberOfInputConnections(0) > 0 ? this->GetInputAlgorithm(0, 0) : nullptr;
  std::string error = vao::checkHistogramBins(this->NumberOfBins);
  std::vector<double> thresholds;
  if (!producer && error.empty())
    error = "no input connection";
  if (error.empty())
  {
    const int port = this->GetInputConnection(0, 0)->GetIndex();
    vtkAmbientOcclusionArrayInput::ScalarVolume scalars; // the slab being read
    bool read = false;
    try // outside RequestData, so outside the filters' memory guard
    {
      read = vtkAmbientOcclusionThresholds::ComputeInSlabs(
        producer, port, slabs, this->NumberOfBins,
        [&](vtkImageData* image, vao::VolumeView& view, std::string& why)
        {
          if (!vtkAmbientOcclusionArrayInput::PrepareScalars(
                this, this->GetInputArrayToProcess(0, image), image, this->Component, scalars, why))
            return false;
          view = scalars.view;
          return true;
        },
        thresholds, error);
    }
    catch (const std::bad_alloc&)
    {
      error = "not enough memory for the value histogram; read the input in more slabs";
    }
    if (!read && error.empty())
      error = "the input could not be read in slabs";
  }
  if (!error.empty())
  {
    vtkErrorMacro(<< "ComputeHistogramThresholds: " << error);
    return nullptr;
  }
  auto array = vtkSmartPointer<vtkDoubleArray>::New();
  array->SetName("HistogramThresholds");
  for (const double t : thresholds)
    array->InsertNextValue(t);
  return array;
}

//------------------------------------------------------------------------------
bool vtkVolumetricAmbientOcclusion::Thresholds(vtkImageData* input, const vao::VolumeView* volume,
  const vao::ValueScan& scan, const int outExt[6], const int whole[6], bool failed,
  std::vector<double>& thresholds)
{
  std::string error;
  if (this->HistogramThresholds)
  {
    for (vtkIdType i = 0; i < this->HistogramThresholds->GetNumberOfTuples(); ++i)
      thresholds.push_back(this->HistogramThresholds->GetComponent(i, 0));
    const vao::Status status = vao::checkHistogramThresholds(thresholds);
    if (!status.ok)
      error = "HistogramThresholds: " + status.message + ".";
  }
  else
  {
    // Distributed: each process counts its output piece (together they tile the data
    // set); one process counts its input, which is the whole extent.
    const bool distributed = this->IsDistributed();
    // One process counts the whole array: its thresholds are kept on it for the next run.
    vtkDataArray* counted =
      !distributed && volume ? this->GetInputArrayToProcess(0, input) : nullptr;
    if (counted &&
      vtkAmbientOcclusionThresholds::Recall(
        counted, this->Component, this->NumberOfBins, thresholds))
      return !failed;
    vtkAmbientOcclusionThresholds::Piece piece;
    piece.volume = volume;
    piece.scan = &scan;
    piece.inExt = volume ? input->GetExtent() : outExt;
    piece.outExt = distributed || !volume ? outExt : input->GetExtent();
    piece.whole = whole;
    piece.failed = failed;
    const bool computed = vtkAmbientOcclusionThresholds::Compute(
      distributed ? this->Controller.Get() : nullptr, piece, this->NumberOfBins, thresholds, error);
    if (!computed && error.empty())
      return false; // aborted, or this process failed and said why before
    if (computed)
      vtkAmbientOcclusionThresholds::Remember(
        counted, this->Component, this->NumberOfBins, thresholds);
  }
  if (!error.empty())
  {
    vtkErrorMacro(<< error);
  }
  return error.empty() && !failed;
}
