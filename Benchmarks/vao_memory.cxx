// Peak resident memory of each filter on one volume (default: the 512x512x209 CT head
// phantom at R = 10), as a table: the input's and the outputs' sizes, the peak, and the
// extra memory (peak - resident before the filter - the new output arrays) against the
// input's size (the volume filters aim at extra <= 25% of the input, the isosurface AO,
// which keeps a moment pyramid's tiles between light moves, at <= 50%).
//
//   vao_memory [CT.mha] [--radius R] [--threads N] [--exact]
//
// Each method runs in a child process of its own (this program re-executed with --child),
// so one method's freed memory does not hide the next one's peak. The child reads the
// volume, resets the kernel's high-water mark (/proc/self/clear_refs, "5"), runs the filter
// and reads VmHWM from /proc/self/status.
#include "BenchmarkSupport.h"
#include "ProcessMemory.h"
#include "vtkAmbientOcclusionShading.h"
#include "vtkIsosurfaceAmbientOcclusion.h"
#include "vtkOcclusionSweeping.h"
#include "vtkVarianceOcclusionMap.h"
#include "vtkVolumetricAmbientOcclusion.h"

#include <vtkAlgorithm.h>
#include <vtkCompositeDataIterator.h>
#include <vtkDataArray.h>
#include <vtkDataSet.h>
#include <vtkFlyingEdges3D.h>
#include <vtkImageData.h>
#include <vtkMetaImageReader.h>
#include <vtkMultiBlockDataSet.h>
#include <vtkNew.h>
#include <vtkPointData.h>
#include <vtkPolyData.h>
#include <vtkSmartPointer.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <vector>

#include <unistd.h>

namespace
{

using vao_bench::ResetPeak;
using vao_bench::StatusBytes;

/// Bytes of the point arrays of `data` (a data set, or the images of a multiblock) that
/// are not among `known` (the inputs' arrays, shared by reference).
long long NewArrayBytes(vtkDataObject* data, const std::set<vtkDataArray*>& known)
{
  long long bytes = 0;
  auto add = [&](vtkDataSet* set)
  {
    vtkPointData* pd = set->GetPointData();
    for (int a = 0; a < pd->GetNumberOfArrays(); ++a)
    {
      vtkDataArray* array = pd->GetArray(a);
      if (array && !known.count(array))
      {
        bytes += array->GetNumberOfValues() * array->GetDataTypeSize();
      }
    }
  };
  if (auto* set = vtkDataSet::SafeDownCast(data))
  {
    add(set);
  }
  else if (auto* blocks = vtkMultiBlockDataSet::SafeDownCast(data))
  {
    vtkSmartPointer<vtkCompositeDataIterator> it;
    it.TakeReference(blocks->NewIterator());
    for (it->InitTraversal(); !it->IsDoneWithTraversal(); it->GoToNextItem())
    {
      if (auto* level = vtkDataSet::SafeDownCast(it->GetCurrentDataObject()))
      {
        add(level);
      }
    }
  }
  return bytes;
}

struct Case
{
  const char* name;
  const char* outputs;
  double bar = 25.0; // the extra memory aimed at, in % of the input
};

const Case kCases[] = {
  { "Histogram CDF", "AmbientOcclusion" }, { "Gaussian CDF", "AmbientOcclusion" },
  { "CDF Reconstruction", "AmbientOcclusion" }, { "Chebyshev", "AmbientOcclusion" },
  { "Gaussian CDF + variance", "AmbientOcclusion, Variance" },
  { "Occlusion Sweeping", "AmbientOcclusion, SignedDistance" },
  { "Variance Occlusion Map", "4 levels of Mean, Variance" }, { "Shading (RGBA)", "ShadedRGBA" },
  { "Isosurface AO + shadows", "AmbientOcclusion, Shadow (bone)", 50.0 },
  { "Isosurface AO, half res.", "AmbientOcclusion, Shadow (bone)", 50.0 },
  { "Exact Box", "AmbientOcclusion" },    // only with --exact (minutes: O(R^3))
  { "Exact Sphere", "AmbientOcclusion" }, // only with --exact
};
constexpr int kFirstExactCase = 10;

/// The filter of case c on `input`, ready to update.
vtkSmartPointer<vtkAlgorithm> MakeFilter(int c, vtkImageData* input, double radius, int threads)
{
  const std::string name = kCases[c].name;
  if (name == "Occlusion Sweeping")
  {
    auto sweep = vtkSmartPointer<vtkOcclusionSweeping>::New();
    sweep->SetIsoValue(-300.0);
    sweep->SetInputData(input);
    return sweep;
  }
  if (name == "Variance Occlusion Map")
  {
    auto map = vtkSmartPointer<vtkVarianceOcclusionMap>::New();
    map->SetInputData(input);
    return map;
  }
  if (name.rfind("Isosurface AO", 0) == 0)
  {
    // The bone surface (400 HU) is made beforehand, as part of the input.
    vtkNew<vtkFlyingEdges3D> contour;
    contour->SetInputData(input);
    contour->SetValue(0, 400.0);
    contour->ComputeNormalsOn();
    contour->Update();
    auto surface = vtkSmartPointer<vtkPolyData>::New();
    surface->ShallowCopy(contour->GetOutput());
    auto shade = vtkSmartPointer<vtkIsosurfaceAmbientOcclusion>::New();
    shade->SetInputData(0, surface);
    shade->SetInputData(1, input);
    shade->SetComputeShadows(true);
    shade->SetStartAtHalfResolution(name.find("half") != std::string::npos);
    return shade;
  }
  if (name == "Shading (RGBA)")
  {
    // The AO array it shades is made beforehand (part of the input here).
    vtkNew<vtkVolumetricAmbientOcclusion> ao;
    ao->SetInputData(input);
    ao->SetRadius(radius);
    ao->Update();
    input->GetPointData()->AddArray(ao->GetOutput()->GetPointData()->GetArray("AmbientOcclusion"));
    auto shading = vtkSmartPointer<vtkAmbientOcclusionShading>::New();
    shading->SetInputData(input);
    return shading;
  }
  auto ao = vtkSmartPointer<vtkVolumetricAmbientOcclusion>::New();
  ao->SetInputData(input);
  ao->SetRadius(radius);
  ao->SetNumberOfThreads(threads);
  ao->SetBackend(vtkVolumetricAmbientOcclusion::BACKEND_CPU);
  ao->SetMethod(name == "CDF Reconstruction" ? vtkVolumetricAmbientOcclusion::CDF_RECONSTRUCTION
      : name == "Chebyshev"                  ? vtkVolumetricAmbientOcclusion::CHEBYSHEV
      : name == "Exact Box"                  ? vtkVolumetricAmbientOcclusion::EXACT_BOX
      : name == "Exact Sphere"               ? vtkVolumetricAmbientOcclusion::EXACT_SPHERE
      : name == "Histogram CDF"              ? vtkVolumetricAmbientOcclusion::HISTOGRAM_CDF
                                             : vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF);
  ao->SetComputeVariance(name == "Gaussian CDF + variance");
  return ao;
}

/// One case, in this (child) process: prints "input output peak extra" in bytes.
int RunChild(int c, const std::string& path, double radius, int threads)
{
  vtkNew<vtkMetaImageReader> reader;
  reader->SetFileName(path.c_str());
  reader->Update();
  vtkNew<vtkImageData> input;
  input->ShallowCopy(reader->GetOutput());
  reader->GetOutput()->Initialize(); // the reader's reference only
  vtkDataArray* scalars = input->GetPointData()->GetScalars();
  if (!scalars)
  {
    std::fprintf(stderr, "no scalars in %s\n", path.c_str());
    return 1;
  }
  const long long inputBytes = scalars->GetNumberOfValues() * scalars->GetDataTypeSize();
  vtkSmartPointer<vtkAlgorithm> filter = MakeFilter(c, input, radius, threads);
  std::set<vtkDataArray*> known; // every input's point arrays
  for (int port = 0; port < filter->GetNumberOfInputPorts(); ++port)
  {
    if (auto* set = vtkDataSet::SafeDownCast(filter->GetInputDataObject(port, 0)))
    {
      for (int a = 0; a < set->GetPointData()->GetNumberOfArrays(); ++a)
      {
        known.insert(set->GetPointData()->GetArray(a));
      }
    }
  }
  if (!ResetPeak())
  {
    std::fprintf(stderr, "cannot reset VmHWM (/proc/self/clear_refs)\n");
    return 1;
  }
  const long long before = StatusBytes("VmRSS:");
  filter->Update();
  const long long peak = StatusBytes("VmHWM:");
  const long long outputBytes = NewArrayBytes(filter->GetOutputDataObject(0), known);
  std::printf(
    "%lld %lld %lld %lld\n", inputBytes, outputBytes, peak - before, peak - before - outputBytes);
  return 0;
}

std::string Mb(long long bytes)
{
  char text[32];
  std::snprintf(text, sizeof text, "%.1f", bytes / 1048576.0);
  return text;
}

} // namespace

int main(int argc, char* argv[])
{
  std::string path =
    vaobench::ScanPath(VAO_EXTRA_DATA_DIR, "ct_head_phantom/ct_head_phantom_512x512x209_int16.mha");
  double radius = 10.0;
  int threads = 0;
  int child = -1;
  bool exact = false;
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    if (a == "--radius" && i + 1 < argc)
      radius = std::atof(argv[++i]);
    else if (a == "--exact")
      exact = true;
    else if (a == "--threads" && i + 1 < argc)
      threads = std::atoi(argv[++i]);
    else if (a == "--child" && i + 1 < argc)
      child = std::atoi(argv[++i]);
    else if (a == "--help" || a == "-h")
    {
      std::printf("usage: vao_memory [CT.mha] [--radius R] [--threads N] [--exact]\n");
      return 0;
    }
    else
      path = a;
  }
  if (child >= 0)
  {
    return RunChild(child, path, radius, threads);
  }

  std::printf("peak resident memory of each filter on %s, R = %g (one process per row)\n",
    path.c_str(), radius);
  std::printf("%-26s %-34s %9s %9s %9s %9s %8s  %s\n", "filter", "new output arrays", "input MB",
    "output MB", "peak MB", "extra MB", "extra %", "bar: extra <= 25% of input (isosurface: 50%)");
  int failures = 0;
  const int cases = exact ? static_cast<int>(sizeof kCases / sizeof kCases[0]) : kFirstExactCase;
  for (int c = 0; c < cases; ++c)
  {
    char resolved[4096];
    const ssize_t n = readlink("/proc/self/exe", resolved, sizeof resolved - 1);
    if (n <= 0)
    {
      std::fprintf(stderr, "cannot find this program (/proc/self/exe)\n");
      return 1;
    }
    resolved[n] = '\0';
    std::ostringstream run;
    run << "'" << resolved << "' --child " << c << " --radius " << radius << " --threads "
        << threads << " '" << path << "'";
    FILE* pipe = popen(run.str().c_str(), "r");
    long long input = 0, output = 0, peak = 0, extra = 0;
    const bool ok =
      pipe && std::fscanf(pipe, "%lld %lld %lld %lld", &input, &output, &peak, &extra) == 4;
    if (pipe)
      pclose(pipe);
    if (!ok)
    {
      std::printf("%-26s failed\n", kCases[c].name);
      ++failures;
      continue;
    }
    const double percent = 100.0 * extra / input;
    std::printf("%-26s %-34s %9s %9s %9s %9s %7.1f%%  %s\n", kCases[c].name, kCases[c].outputs,
      Mb(input).c_str(), Mb(output).c_str(), Mb(peak).c_str(), Mb(extra).c_str(), percent,
      percent <= kCases[c].bar ? "PASS" : "FAIL");
  }
  return failures ? 1 : 0;
}
