// vao-demo's volume file (DemoVolumeFile.cxx).
#pragma once

#include "DemoCommon.h"

#include "vtkSmartPointer.h"

#include <string>
#include <vector>

class vtkImageData;

namespace vaodemo
{

/// The input's structure with `scalars` and every result array.
vtkSmartPointer<vtkImageData> AssembleResult(
  vtkImageData* input, vtkDataArray* scalars, const std::vector<Computation>& results);

/// Writes `image` as a .vti with inline binary data (this VTK reads appended data back
/// wrongly); fails (DemoError) when the writer does.
void WriteVolume(vtkImageData* image, const std::string& path);

/// Reads `path` back with VTK's reader and fails unless every array equals `written`'s.
void CheckVolumeReadBack(vtkImageData* written, const std::string& path);

} // namespace vaodemo
