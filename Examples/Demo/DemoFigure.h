// vao-demo's figure (DemoFigure.cxx).
#pragma once

#include "DemoCommon.h"

#include <string>
#include <vector>

class vtkImageData;

namespace vaodemo
{

/// The figure of `results` on the middle slice normal to `sliceAxis` (a row per method,
/// a column per radius, the input on top) as a PNG at `path`, read back to check it; a
/// legend file beside it when no font renders the labels. Fails (DemoError) on I/O errors.
void WriteFigure(vtkImageData* image, vtkDataArray* scalars,
  const std::vector<Computation>& results, const std::vector<int>& radii, int sliceAxis,
  const std::string& path);

} // namespace vaodemo
