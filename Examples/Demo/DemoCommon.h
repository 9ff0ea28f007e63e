// What the parts of vao-demo share: failures as one exception, the methods of the
// table and the figure, one filter run's result, and VTK error capture.
#pragma once

#include "vtkVolumetricAmbientOcclusion.h"

#include "vtkCommand.h"
#include "vtkDataArray.h"
#include "vtkObject.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <array>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

namespace vaodemo
{

constexpr int ExitFailure = 1;
constexpr int ExitBadInput = 2;

/// Every failure ends the program through this exception, caught once in main: the
/// functions below stay free of error plumbing.
struct DemoError
{
  int exitCode;
  std::string message;
};

[[noreturn]] inline void Fail(int exitCode, const std::string& message)
{
  throw DemoError{ exitCode, message };
}

//------------------------------------------------------------------------------
// The methods, in the row order of the figure (Fig. 6 of Ruiz et al. first, then this
// project's Histogram CDF, the two exact references, and the smoothed query's rows).
struct MethodInfo
{
  int id;            // vtkVolumetricAmbientOcclusion::MethodType
  const char* label; // for people: table rows and figure labels
  const char* key;   // for arrays: "<key>_R<radius>"
  int query = vtkVolumetricAmbientOcclusion::VOXEL_VALUE;
};

constexpr int Smoothed = vtkVolumetricAmbientOcclusion::SMOOTHED_VALUE;
inline const std::array<MethodInfo, 8> Methods = { {
  { vtkVolumetricAmbientOcclusion::CHEBYSHEV, "Chebyshev (Penner)", "Chebyshev" },
  { vtkVolumetricAmbientOcclusion::CDF_RECONSTRUCTION, "CDF Reconstruction", "CDFReconstruction" },
  { vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF, "Gaussian CDF", "GaussianCDF" },
  { vtkVolumetricAmbientOcclusion::HISTOGRAM_CDF, "Histogram CDF", "HistogramCDF" },
  { vtkVolumetricAmbientOcclusion::EXACT_BOX, "Exact Box", "ExactBox" },
  { vtkVolumetricAmbientOcclusion::EXACT_SPHERE, "Exact Sphere", "ExactSphere" },
  { vtkVolumetricAmbientOcclusion::HISTOGRAM_CDF, "Histogram CDF, smooth q", "HistogramCDFSmoothed",
    Smoothed },
  { vtkVolumetricAmbientOcclusion::EXACT_BOX, "Exact Box, smooth q", "ExactBoxSmoothed", Smoothed },
} };

/// The row of method `id` with query mode `query`.
inline const MethodInfo& MethodWithId(
  int id, int query = vtkVolumetricAmbientOcclusion::VOXEL_VALUE)
{
  return *std::find_if(Methods.begin(), Methods.end(),
    [id, query](const MethodInfo& m) { return m.id == id && m.query == query; });
}

/// The oracle a row is compared with (docs/methods.md): Exact Box with the same query.
inline const MethodInfo& ReferenceOf(const MethodInfo& method)
{
  return MethodWithId(vtkVolumetricAmbientOcclusion::EXACT_BOX, method.query);
}

inline std::string ArrayName(const char* key, int radius)
{
  return std::string(key) + "_R" + std::to_string(radius);
}

//------------------------------------------------------------------------------

//------------------------------------------------------------------------------
/// Catches the error messages of a VTK object, so that a failure is reported once, in the
/// demo's words, instead of as VTK's multi-line output-window text.
class ErrorLog
{
public:
  explicit ErrorLog(vtkObject* object)
    : Object(object)
    , Tag(object->AddObserver(vtkCommand::ErrorEvent, this, &ErrorLog::OnError))
  {
  }
  ~ErrorLog() { this->Object->RemoveObserver(this->Tag); }
  ErrorLog(const ErrorLog&) = delete;
  ErrorLog& operator=(const ErrorLog&) = delete;

  /// The messages so far, or `fallback` when there were none.
  std::string Text(const std::string& fallback) const
  {
    return this->Messages.empty() ? fallback : this->Messages;
  }

private:
  void OnError(vtkObject*, unsigned long, void* callData)
  {
    // VTK prefixes "ClassName (0x...): "; the class name means nothing to a user.
    std::string message = static_cast<const char*>(callData);
    const std::size_t prefix = message.find("): ");
    if (prefix != std::string::npos)
    {
      message.erase(0, prefix + 3);
    }
    while (!message.empty() && (message.back() == '\n' || message.back() == ' '))
    {
      message.pop_back();
    }
    this->Messages += (this->Messages.empty() ? "" : "; ") + message;
  }

  vtkObject* Object;
  unsigned long Tag;
  std::string Messages;
};

//------------------------------------------------------------------------------
// Input.
//------------------------------------------------------------------------------
// Computation.
struct Computation
{
  const MethodInfo* method; // null for the Variance
  int radius;
  double seconds;
  vtkSmartPointer<vtkDataArray> values; // named as in the .vti
};

inline std::string Format(const char* format, double value)
{
  char text[64];
  std::snprintf(text, sizeof(text), format, value);
  return text;
}

inline double SecondsSince(std::chrono::steady_clock::time_point start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

/// One filter run: its openness array named "<key>_R<radius>", or with `variance` its

/// The computation of `method` at `radius` (it must exist).
inline const Computation& Find(
  const std::vector<Computation>& results, const MethodInfo* method, int radius)
{
  for (const Computation& c : results)
  {
    if (c.method == method && c.radius == radius)
    {
      return c;
    }
  }
  Fail(ExitFailure, "internal error: a computation is missing.");
}

} // namespace vaodemo
