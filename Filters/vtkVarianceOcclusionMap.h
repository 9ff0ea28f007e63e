/**
 * @class   vtkVarianceOcclusionMap
 * @brief   The moment pyramid of Penner & Mitchell 2008 (variance occlusion maps).
 *
 * Blurs the first two moments of the volume with a 5x5x5 Gaussian, then builds a
 * pyramid: each level blurs the previous one and halves its resolution (the effective
 * kernel doubles). The output is a multiblock of vtkImageData levels, each with its own
 * origin and spacing and the float32 point arrays "Mean" and "Variance". Use it to look
 * at the maps, or to sample them with the Probe filter; Isosurface Ambient Occlusion
 * builds the same pyramid internally and keeps it between updates. Distributed or
 * streamed, a piece reads its extent grown by the pyramid's reach (2^levels input voxels;
 * 2^(levels+1) - 2 from half resolution) and outputs the level voxels of its piece.
 *
 * Threads: the filter computes on its own pool of threads, NumberOfThreads of them (0,
 * the default: the cores this process may use; under MPI, its share of the node's cores).
 * VTK's SMP settings (vtkSMPTools, VTK_SMP_MAX_THREADS, VTK_SMP_BACKEND_IN_USE) do not
 * apply: the default SMP backend of Debian 12's VTK 9.2 and ParaView 5.11 is Sequential
 * (one thread), and the kernels the filter runs are a library that builds without VTK.
 */
#ifndef vtkVarianceOcclusionMap_h
#define vtkVarianceOcclusionMap_h

#include "VolumetricAOFiltersModule.h" // for export macro
#include "vtkMultiBlockDataSetAlgorithm.h"

namespace vao
{
struct PyramidParameters;
}

class VOLUMETRICAOFILTERS_EXPORT vtkVarianceOcclusionMap : public vtkMultiBlockDataSetAlgorithm
{
public:
  static vtkVarianceOcclusionMap* New();
  vtkTypeMacro(vtkVarianceOcclusionMap, vtkMultiBlockDataSetAlgorithm);
  void PrintSelf(ostream& os, vtkIndent indent) override;

  ///@{
  /// Number of pyramid levels (default 4, at most 16).
  vtkSetMacro(NumberOfLevels, int);
  vtkGetMacro(NumberOfLevels, int);
  ///@}

  ///@{
  /// Start the pyramid at half resolution (default off): level 0 has an eighth of the
  /// voxels, for large volumes.
  vtkSetMacro(StartAtHalfResolution, vtkTypeBool);
  vtkGetMacro(StartAtHalfResolution, vtkTypeBool);
  vtkBooleanMacro(StartAtHalfResolution, vtkTypeBool);
  ///@}

  ///@{
  /// Component of a multi-component input array; -1 (default): single-component only.
  vtkSetMacro(Component, int);
  vtkGetMacro(Component, int);
  ///@}

  ///@{
  /// Threads of the pyramid's build on this process; 0 (default): the cores available to
  /// the process, divided among the MPI ranks on its node. Negative values are an error.
  vtkSetMacro(NumberOfThreads, int);
  vtkGetMacro(NumberOfThreads, int);
  ///@}

protected:
  vtkVarianceOcclusionMap();
  ~vtkVarianceOcclusionMap() override = default;

  int FillInputPortInformation(int port, vtkInformation* info) override;
  int RequestUpdateExtent(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;
  int RequestData(vtkInformation*, vtkInformationVector**, vtkInformationVector*) override;

  int NumberOfLevels = 4;
  vtkTypeBool StartAtHalfResolution = false;
  int Component = -1;
  int NumberOfThreads = 0;

private:
  /// The kernel's pyramid parameters.
  vao::PyramidParameters Parameters() const;
  /// The input extent a piece needs: the piece grown by the pyramid's reach, its lower
  /// end aligned on the coarsest level's voxels.
  void InputExtentOf(const int whole[6], const int piece[6], int ext[6]) const;

  vtkVarianceOcclusionMap(const vtkVarianceOcclusionMap&) = delete;
  void operator=(const vtkVarianceOcclusionMap&) = delete;

  /// The levels of each volume of a composite input.
  int ProduceEachVolume(vtkInformationVector** inputVector, vtkInformationVector* outputVector);
  /// The pyramid's levels of the requested piece (RequestData's body, inside its memory
  /// guard).
  int ProduceOutput(vtkInformationVector** inputVector, vtkInformationVector* outputVector);
};

#endif
