// The Penner & Mitchell tables of vao_benchmark (PennerRows.cxx).
#pragma once

#include "BenchmarkSupport.h"

class vtkImageData;

namespace vaobench
{

/// The pyramid builds of the paper's Table 1 sizes, each against its floor row, and on
/// 256^3 scipy.ndimage's level-0 blur in the same run.
void BenchmarkPyramid(const Options& options);

/// AO, shadow and AO + shadow rates on the bone surface (400 HU) of a CT head.
void BenchmarkRelighting(const Options& options, const char* name, vtkImageData* ct);

} // namespace vaobench
