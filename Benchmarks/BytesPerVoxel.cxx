// The bytes each kernel moves per voxel, measured by valgrind's cache simulation (callgrind
// --cache-sim=yes): this machine's virtual processor has no hardware counters, and the
// simulation counts every load and store the kernel makes through a model of the caches.
// The table runs this program again under valgrind once per workload (--bytes-of NAME),
// which builds its input uninstrumented and turns the instrumentation on around the kernel
// call alone. Memory traffic: a 64-byte line for each miss of the simulated last level
// (read, or allocated for a write) and for each dirty line it evicts (--simulate-wb).
#include "BytesPerVoxel.h"

#include "SweepScene.h"
#include "vtkAmbientOcclusionPhantom.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkSmartPointer.h"

#include "vao/AmbientOcclusion.h"
#include "vao/HistogramCdf.h"
#include "vao/OcclusionSweeping.h"
#include "vao/Storage.h"
#include "vao/VarianceOcclusionMap.h"

#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define VAO_HAVE_CALLGRIND 1
#else
#define VAO_HAVE_CALLGRIND 0
#define CALLGRIND_START_INSTRUMENTATION
#define CALLGRIND_STOP_INSTRUMENTATION
#endif

#include <unistd.h>

#include <cstdio>
#include <map>
#include <sstream>
#include <string>
#include <vector>

namespace vaobench
{
namespace
{

/// The simulated caches: a Zen 5 core's 48 KiB L1d and a 4 MiB last level, about one
/// core's share of a shared L3; the inputs below are several times larger.
const char* const kCacheModel = "--D1=49152,12,64 --LL=4194304,16,64";

/// The inputs: the generated int16 phantom (8.4 M voxels, 16.8 MB) and, for the sweeping,
/// the Fig. 3 scene in float32 (4.1 M voxels, 16 MB in, 180 MB out).
constexpr int kPhantom[3] = { 256, 256, 128 };
constexpr int kScene = 160;

/// One kernel call measured: the bytes a pass must move per voxel (its input read once,
/// each output written once).
struct Workload
{
  const char* name;
  const char* what;
  double mustMove;
};

const Workload kWorkloads[] = {
  { "floor", "int16 in, float32 out, one loop", 6.0 },
  { "gaussian", "Gaussian CDF, R = 10", 6.0 },
  { "chebyshev", "Chebyshev, R = 10", 6.0 },
  { "cdf", "CDF Reconstruction, R = 10", 6.0 },
  { "histogram", "Histogram CDF (64), R = 10", 6.0 },
  { "pyramid", "variance pyramid, 4 levels", 2.0 + 8.0 * (1.0 + 1.0 / 8 + 1.0 / 64 + 1.0 / 512) },
  { "sweeping", "sweeping, 8 octants (float32)", 4.0 + 4.0 + 4.0 + 32.0 },
};

/// The generated int16 phantom of the benchmark, kPhantom in size.
vtkSmartPointer<vtkImageData> Phantom()
{
  vtkNew<vtkAmbientOcclusionPhantom> phantom;
  phantom->SetDimensions(kPhantom[0], kPhantom[1], kPhantom[2]);
  phantom->Update();
  return phantom->GetOutput();
}

/// Runs workload `name` with the instrumentation on around the kernel alone; 0 on success.
/// `phantom`: the int16 workloads' input, generated on first use (a run of every workload
/// then generates it once).
int RunOne(const std::string& name, vtkSmartPointer<vtkImageData>& phantom)
{
  if (name == "sweeping")
  {
    const int n = kScene;
    const std::vector<float> volume = vaotest::SceneVolume(n, n, n);
    vao::VolumeView view;
    view.data = volume.data();
    view.type = vao::ScalarType::Float32;
    view.dims = { n, n, n };
    const std::size_t voxels = static_cast<std::size_t>(view.voxelCount());
    vao::StorageArray<float> distance, ao, octants;
    distance.resize(voxels);
    ao.resize(voxels);
    octants.resize(8 * voxels);
    vao::SweepParameters parameters;
    parameters.isoValue = 0.5;
    CALLGRIND_START_INSTRUMENTATION;
    const vao::Status s = vao::computeOcclusionSweeping(
      view, { 1.0, 1.0, 1.0 }, parameters, { distance.data(), ao.data(), octants.data() });
    CALLGRIND_STOP_INSTRUMENTATION;
    return s.ok ? 0 : 1;
  }
  if (!phantom)
    phantom = Phantom();
  vao::VolumeView view;
  view.data = phantom->GetScalarPointer();
  view.type = vao::ScalarType::Int16;
  const int* d = phantom->GetDimensions();
  view.dims = { d[0], d[1], d[2] };
  const std::size_t voxels = static_cast<std::size_t>(view.voxelCount());
  vao::StorageArray<float> out; // untouched, as a filter's new output array
  out.resize(voxels);
  if (name == "floor")
  {
    const short* in = static_cast<const short*>(view.data);
    CALLGRIND_START_INSTRUMENTATION;
    for (std::size_t i = 0; i < voxels; ++i)
      out[i] = static_cast<float>(in[i]);
    CALLGRIND_STOP_INSTRUMENTATION;
    return out[voxels / 2] == static_cast<float>(in[voxels / 2]) ? 0 : 1;
  }
  if (name == "pyramid")
  {
    std::vector<vao::MomentLevel> pyramid;
    CALLGRIND_START_INSTRUMENTATION;
    const vao::Status s = vao::buildMomentPyramid(view, { 0, 0, 0 }, { 1, 1, 1 }, {}, pyramid);
    CALLGRIND_STOP_INSTRUMENTATION;
    return s.ok ? 0 : 1;
  }
  vao::AmbientOcclusionParameters p;
  p.radius = { 10, 10, 10 };
  if (name == "gaussian")
    p.method = vao::Method::GaussianCdf;
  else if (name == "chebyshev")
    p.method = vao::Method::Chebyshev;
  else if (name == "cdf")
    p.method = vao::Method::CdfReconstruction;
  else if (name == "histogram")
    p.method = vao::Method::HistogramCdf;
  else
  {
    std::fprintf(stderr, "unknown workload %s\n", name.c_str());
    return 2;
  }
  vao::AmbientOcclusionOutput output;
  output.openness = out.data();
  CALLGRIND_START_INSTRUMENTATION;
  // The Histogram CDF's thresholds are part of its run (a pass over the values).
  if (p.method == vao::Method::HistogramCdf && !vao::volumeThresholds(view, 64, p.thresholds).ok)
    return 1;
  const vao::Status s = vao::computeAmbientOcclusion(view, vao::Region::whole(view), p, output);
  CALLGRIND_STOP_INSTRUMENTATION;
  return s.ok ? 0 : 1;
}

/// The events callgrind collected, by name ("Events :" and "Collected :" of its summary).
std::map<std::string, double> CollectedEvents(const std::string& text)
{
  std::map<std::string, double> events;
  const std::size_t names = text.find("Events    :"), values = text.find("Collected :");
  if (names == std::string::npos || values == std::string::npos)
    return events;
  std::istringstream n(text.substr(names + 11, text.find('\n', names) - names - 11));
  std::istringstream v(text.substr(values + 11, text.find('\n', values) - values - 11));
  std::string name;
  double value = 0.0;
  while (n >> name && v >> value)
    events[name] = value;
  return events;
}

} // namespace

int RunBytesWorkload(const std::string& name)
{
  vtkSmartPointer<vtkImageData> phantom;
  if (name != "all")
    return RunOne(name, phantom);
  for (const Workload& w : kWorkloads) // the ctest that keeps the table's runs working
    if (const int status = RunOne(w.name, phantom))
    {
      std::fprintf(stderr, "workload %s failed\n", w.name);
      return status;
    }
  std::printf("every workload ran\n");
  return 0;
}

void BenchmarkBytes()
{
  std::printf(
    "\nBytes moved per voxel (valgrind's cache simulation of %s): 'memory', a\n"
    "  64-byte line per last-level miss and per dirty line written back; 'L1', a line per L1d\n"
    "  miss; 'must', the input read once and each output written once (a cache that allocates\n"
    "  lines for writes reads each output line first: the floor's 1.6x). Int16 workloads on the\n"
    "  %d x %d x %d generated phantom, the sweeping on the %d^3 Fig. 3 scene\n",
    kCacheModel, kPhantom[0], kPhantom[1], kPhantom[2], kScene);
  if (!VAO_HAVE_CALLGRIND)
  {
    std::printf("  not measured: built without valgrind/callgrind.h (apt-get install valgrind)\n");
    return;
  }
  char self[4096] = {};
  if (readlink("/proc/self/exe", self, sizeof(self) - 1) <= 0)
  {
    std::printf("  not measured: cannot find this program's path\n");
    return;
  }
  std::printf("  %-32s %8s %10s %8s %10s\n", "workload", "must", "memory", "x must", "L1");
  for (const Workload& w : kWorkloads)
  {
    const std::string command =
      std::string("valgrind --tool=callgrind --cache-sim=yes --simulate-wb=yes ") +
      "--instr-atstart=no " + kCacheModel + " --callgrind-out-file=/dev/null '" + self +
      "' --bytes-of " + w.name + " 2>&1";
    std::string text;
    if (FILE* pipe = popen(command.c_str(), "r"))
    {
      char line[512];
      while (std::fgets(line, sizeof(line), pipe))
        text += line;
      if (pclose(pipe) != 0)
        text.clear();
    }
    const double voxels = std::string(w.name) == "sweeping"
      ? double(kScene) * kScene * kScene
      : double(kPhantom[0]) * kPhantom[1] * kPhantom[2];
    std::map<std::string, double> e = CollectedEvents(text);
    if (!e.count("DLmr") || !e.count("DLdmw"))
    {
      std::printf("  %-32s could not run valgrind on it (apt-get install valgrind)\n", w.what);
      continue;
    }
    const double lines = e["DLmr"] + e["DLmw"] + e["ILmr"] + e["DLdmr"] + e["DLdmw"] + e["ILdmr"];
    const double memory = 64.0 * lines / voxels;
    std::printf("  %-32s %8.1f %10.1f %7.2fx %10.1f\n", w.what, w.mustMove, memory,
      memory / w.mustMove, 64.0 * (e["D1mr"] + e["D1mw"]) / voxels);
    std::fflush(stdout);
  }
}

} // namespace vaobench
