// Benchmark: the filter's time for each method at R = 5 and 10 on a 256x256x415 volume
// (the CT-body size of Ruiz et al. Table 1) and on the 512x512x209 CT head phantom, and,
// measured in the same run, scipy.ndimage computing the same statistics.
//
// Then occlusion sweeping (distance only, with the occlusion, with the 8 octants) on the
// generated scenes of Singh et al.'s Table 2 sizes and the CT head phantom's skin, against
// scipy.ndimage.distance_transform_edt in the same run.
//
// Usage: vao_benchmark [--data DIR] [--scipy PATH/TO/scipy_peer.py] [--repeat N]
//                      [--exact] [--threads N] [--volumetric | --sweeping | --penner | --relight |
//                      --bytes] (one table only; --relight: the surface query rates alone; --bytes:
//                      the bytes per voxel each kernel moves, under valgrind, BytesPerVoxel.cxx)
// Last, the variance occlusion maps (PennerRows.cxx): pyramid builds against their floor
// and scipy's level-0 blur, and the surface query rates (AO, soft shadows) on the CT heads'
// bone surfaces.
// Exact Box and Exact Sphere are O(R^3) references: by default they are timed on a
// 32-slice slab and the whole-volume time is extrapolated (marked "~"); --exact times
// them on the whole volume (minutes). Exact Rays (128 rays, through a bone opacity) is
// always timed on 4 middle slices and extrapolated; Rays (the same opacity) on the whole
// volume.
#include "vtkAmbientOcclusionPhantom.h"
#include "vtkVolumetricAmbientOcclusion.h"

#include "BenchmarkSupport.h"
#include "BytesPerVoxel.h"
#include "PennerRows.h"
#include "SweepScene.h"
#include "vao/AmbientOcclusion.h"
#include "vao/OcclusionSweeping.h"
#include "vao/Storage.h"

#include "vtkExtractVOI.h"
#include "vtkImageData.h"
#include "vtkMetaImageReader.h"
#include "vtkNew.h"
#include "vtkPiecewiseFunction.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace
{

using namespace vaobench;

/// The opacity of the methods that read one: soft tissue faint, bone (above 300) shown.
vtkSmartPointer<vtkPiecewiseFunction> BoneOpacity()
{
  auto opacity = vtkSmartPointer<vtkPiecewiseFunction>::New();
  opacity->AddPoint(-200.0, 0.0);
  opacity->AddPoint(100.0, 0.05);
  opacity->AddPoint(300.0, 0.3);
  opacity->AddPoint(1200.0, 0.9);
  return opacity;
}

/// Best of `repeat` wall-clock times of one filter update on an in-memory image.
double TimeFilter(vtkImageData* image, int method, int radius, int repeat, int threads)
{
  double best = 1e300;
  for (int r = 0; r < repeat; ++r)
  {
    vtkNew<vtkVolumetricAmbientOcclusion> filter;
    filter->SetInputData(image);
    filter->SetMethod(method);
    filter->SetOpacityFunction(BoneOpacity());
    filter->SetRadius(radius);
    filter->SetNumberOfThreads(threads);
    const auto start = std::chrono::steady_clock::now();
    filter->Update();
    best = std::min(best, Seconds(start));
    if (filter->GetOutput()->GetNumberOfPoints() != image->GetNumberOfPoints())
    {
      std::fprintf(stderr, "the filter failed\n");
      std::exit(1);
    }
  }
  return best;
}

/// The same statistics scipy computes (mean, variance, minimum, maximum), in doubles.
double TimeStatistics(vtkImageData* image, int radius, int repeat, int threads)
{
  vao::VolumeView view;
  view.data = image->GetScalarPointer();
  view.type = vao::ScalarType::Int16;
  const int* d = image->GetDimensions();
  view.dims = { d[0], d[1], d[2] };
  const size_t n = static_cast<size_t>(image->GetNumberOfPoints());
  std::vector<double> mean(n), variance(n), lo(n), hi(n);
  vao::Execution execution;
  execution.threads = threads;
  double best = 1e300;
  for (int r = 0; r < repeat; ++r)
  {
    const auto start = std::chrono::steady_clock::now();
    vao::computeBoxStatistics(view, vao::Region::whole(view), { radius, radius, radius },
      { nullptr, mean.data(), variance.data(), lo.data(), hi.data() }, execution);
    best = std::min(best, Seconds(start));
  }
  return best;
}

/// The floor: one pass that reads the int16 input once and writes a fresh float32 array
/// once (first touch included, in the storage the filter's output gets), on the same
/// number of threads.
double TimeFloor(vtkImageData* image, int repeat, int threads)
{
  const auto* in = static_cast<const short*>(image->GetScalarPointer());
  const std::int64_t n = image->GetNumberOfPoints();
  const int team = ResolvedThreads(threads);
  double best = 1e300;
  for (int r = 0; r < repeat; ++r)
  {
    const auto start = std::chrono::steady_clock::now();
    vao::StorageArray<float> out; // untouched, like a new output array
    out.resize(static_cast<std::size_t>(n));
    std::vector<std::thread> workers;
    for (int t = 0; t < team; ++t)
    {
      workers.emplace_back(
        [&, t]
        {
          const std::int64_t begin = n * t / team, end = n * (t + 1) / team;
          for (std::int64_t i = begin; i < end; ++i)
            out[i] = static_cast<float>(in[i]);
        });
    }
    for (auto& w : workers)
      w.join();
    best = std::min(best, Seconds(start));
    if (out[n / 2] != static_cast<float>(in[n / 2]))
      std::exit(1); // keeps the pass from being optimised away
  }
  return best;
}

/// Runs the scipy peer on a file; returns seconds per radius (empty when it cannot run).
std::map<int, double> RunScipy(const Options& options, const std::string& volumeFile)
{
  std::map<int, double> seconds;
  const std::string command = "/usr/bin/python3 '" + options.scipy + "' '" + volumeFile + "' 5 10";
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe)
  {
    return seconds;
  }
  char line[256];
  while (std::fgets(line, sizeof(line), pipe))
  {
    int radius = 0;
    double time = 0;
    if (std::sscanf(line, "scipy %d %lf", &radius, &time) == 2)
    {
      seconds[radius] = time;
    }
  }
  pclose(pipe);
  return seconds;
}

void Benchmark(const std::string& label, vtkImageData* image, const std::string& scipyFile,
  const Options& options)
{
  const int* d = image->GetDimensions();
  const double voxels = static_cast<double>(image->GetNumberOfPoints());
  std::printf("\n%s: %d x %d x %d int16 (%.1f M voxels), %d threads\n", label.c_str(), d[0], d[1],
    d[2], voxels / 1e6, ResolvedThreads(options.threads));
  const double floor = TimeFloor(image, std::max(3, options.repeat), options.threads);
  // Bytes one pass must move: the int16 input read once, the float32 output written once.
  std::printf(
    "  floor (read int16 once, write float32 once): %.1f ms, %.1f GB/s; each method below as\n"
    "  time [ms] and (x floor)\n",
    1e3 * floor, 6.0 * voxels / floor / 1e9);
  std::printf("  %-20s %17s %17s\n", "method", "R = 5", "R = 10");
  // Histogram CDF (the default) first; the peers it is measured against follow.
  const int methods[] = { vtkVolumetricAmbientOcclusion::HISTOGRAM_CDF,
    vtkVolumetricAmbientOcclusion::CDF_RECONSTRUCTION, vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF,
    vtkVolumetricAmbientOcclusion::CHEBYSHEV, vtkVolumetricAmbientOcclusion::EXACT_BOX,
    vtkVolumetricAmbientOcclusion::EXACT_SPHERE };
  const char* names[] = { "CDF Reconstruction", "Gaussian CDF", "Chebyshev", "Exact Box",
    "Exact Sphere", "Histogram CDF (64)" };
  std::map<int, std::map<int, double>> seconds; // method -> radius -> time
  for (const int method : methods)
  {
    std::printf("  %-20s", names[method]);
    for (int radius : { 5, 10 })
    {
      const bool reference = method == vtkVolumetricAmbientOcclusion::EXACT_BOX ||
        method == vtkVolumetricAmbientOcclusion::EXACT_SPHERE;
      if (reference && !options.exact)
      {
        // A 32-slice slab, extrapolated by voxel count (the cost is uniform per voxel).
        vtkNew<vtkExtractVOI> slab;
        slab->SetInputData(image);
        const int* e = image->GetExtent();
        slab->SetVOI(e[0], e[1], e[2], e[3], e[4], e[4] + 31);
        slab->Update();
        const double t = TimeFilter(slab->GetOutput(), method, radius, 1, options.threads);
        seconds[method][radius] = t * voxels / slab->GetOutput()->GetNumberOfPoints();
        std::printf(
          " %8.0f~ (%4.0fx)", 1e3 * seconds[method][radius], seconds[method][radius] / floor);
      }
      else
      {
        seconds[method][radius] =
          TimeFilter(image, method, radius, options.repeat, options.threads);
        std::printf(
          " %8.1f (%5.1fx)", 1e3 * seconds[method][radius], seconds[method][radius] / floor);
      }
      std::fflush(stdout);
    }
    std::printf("\n");
  }
  {
    // Exact Rays (128 rays) through BoneOpacity: 4 middle slices, extrapolated by voxel count.
    std::printf("  %-20s", "Exact Rays (128)");
    vtkNew<vtkExtractVOI> slab;
    slab->SetInputData(image);
    const int* e = image->GetExtent();
    const int middle = (e[4] + e[5]) / 2;
    slab->SetVOI(e[0], e[1], e[2], e[3], middle, std::min(middle + 3, e[5]));
    slab->Update();
    for (int radius : { 5, 10 })
    {
      const double t = TimeFilter(
        slab->GetOutput(), vtkVolumetricAmbientOcclusion::EXACT_RAYS, radius, 1, options.threads);
      seconds[vtkVolumetricAmbientOcclusion::EXACT_RAYS][radius] =
        t * voxels / slab->GetOutput()->GetNumberOfPoints();
      std::printf(" %8.0f~ (%4.0fx)",
        1e3 * seconds[vtkVolumetricAmbientOcclusion::EXACT_RAYS][radius],
        seconds[vtkVolumetricAmbientOcclusion::EXACT_RAYS][radius] / floor);
      std::fflush(stdout);
    }
    std::printf("\n");
  }
  {
    // Rays through BoneOpacity, on the whole volume.
    std::printf("  %-20s", "Rays");
    for (int radius : { 5, 10 })
    {
      seconds[vtkVolumetricAmbientOcclusion::RAYS][radius] = TimeFilter(
        image, vtkVolumetricAmbientOcclusion::RAYS, radius, options.repeat, options.threads);
      std::printf(" %8.1f (%5.1fx)", 1e3 * seconds[vtkVolumetricAmbientOcclusion::RAYS][radius],
        seconds[vtkVolumetricAmbientOcclusion::RAYS][radius] / floor);
      std::fflush(stdout);
    }
    std::printf("\n");
  }
  const auto& histogram = seconds[vtkVolumetricAmbientOcclusion::HISTOGRAM_CDF];
  const auto& gaussian = seconds[vtkVolumetricAmbientOcclusion::GAUSSIAN_CDF];
  const auto& rays = seconds[vtkVolumetricAmbientOcclusion::EXACT_RAYS];
  const auto& exactBox = seconds[vtkVolumetricAmbientOcclusion::EXACT_BOX];
  std::printf("  %-20s %11.2fx %11.2fx   (bar: at most 2.5x)\n", "Histogram / Gaussian",
    histogram.at(5) / gaussian.at(5), histogram.at(10) / gaussian.at(10));
  std::printf("  %-20s %11.0fx %11.0fx   (bar: at least 20x at R = 5)\n", "Exact Box / Histogram",
    exactBox.at(5) / histogram.at(5), exactBox.at(10) / histogram.at(10));
  std::printf("  %-20s %11.0fx %11.0fx\n", "Exact Rays / Gaussian", rays.at(5) / gaussian.at(5),
    rays.at(10) / gaussian.at(10));
  const auto& fast = seconds[vtkVolumetricAmbientOcclusion::RAYS];
  std::printf("  %-20s %11.1fx %11.1fx   (goal: at most 4x at R = 10)\n", "Rays / Gaussian",
    fast.at(5) / gaussian.at(5), fast.at(10) / gaussian.at(10));
  const double stats5 = TimeStatistics(image, 5, options.repeat, options.threads);
  const double stats10 = TimeStatistics(image, 10, options.repeat, options.threads);
  std::printf("  %-20s %12.1f %12.1f\n", "statistics (ours)", 1e3 * stats5, 1e3 * stats10);
  const auto scipy = RunScipy(options, scipyFile);
  if (scipy.size() == 2)
  {
    std::printf("  %-20s %12.1f %12.1f\n", "scipy.ndimage", 1e3 * scipy.at(5), 1e3 * scipy.at(10));
    std::printf(
      "  %-20s %11.1fx %11.1fx\n", "speed-up", scipy.at(5) / stats5, scipy.at(10) / stats10);
  }
  else
  {
    std::printf(
      "  scipy.ndimage: could not run %s (python3-scipy missing?)\n", options.scipy.c_str());
  }
}

/// A MetaImage scan (ScanPath); exits with a message when it cannot be read.
vtkSmartPointer<vtkImageData> ReadScanOrExit(const std::string& path)
{
  // The reader gives a one-point image for a file that is not there: look first.
  vtkNew<vtkMetaImageReader> reader;
  reader->SetFileName(path.c_str());
  if (std::ifstream(path).good())
    reader->Update();
  if (reader->GetOutput()->GetNumberOfPoints() <= 1)
  {
    std::fprintf(stderr,
      "cannot read %s (a scan not shipped in Data/: pass --data DIR, or configure with "
      "-DVAO_EXTRA_DATA_DIR=DIR)\n",
      path.c_str());
    std::exit(1);
  }
  return reader->GetOutput();
}

/// The scipy EDT peer's seconds: the unsigned distance and the signed one (negative when
/// it could not run).
struct EdtPeer
{
  double unsignedSeconds = -1.0;
  double signedSeconds = -1.0;
};

/// Runs the scipy EDT peer on a raw float32 volume.
EdtPeer RunScipyEdt(const Options& options, const std::string& volumeFile, double iso)
{
  const std::string command =
    "/usr/bin/python3 '" + options.scipyEdt + "' '" + volumeFile + "' " + std::to_string(iso);
  FILE* pipe = popen(command.c_str(), "r");
  EdtPeer peer;
  char line[256];
  while (pipe && std::fgets(line, sizeof(line), pipe))
  {
    std::sscanf(line, "edt %lf", &peer.unsignedSeconds);
    std::sscanf(line, "signed %lf", &peer.signedSeconds);
  }
  if (pipe)
  {
    pclose(pipe);
  }
  return peer;
}

/// Best of `repeat` runs of the sweeping kernel: distance only, with the combined
/// occlusion, or with the 8 octants written out.
double TimeSweeping(const vao::VolumeView& view, const std::array<double, 3>& spacing, double iso,
  int outputs, int repeat, std::vector<float>& distance, std::vector<float>& ao,
  std::vector<float>& octants)
{
  vao::SweepParameters parameters;
  parameters.isoValue = iso;
  const vao::SweepOutput output{ distance.data(), outputs >= 1 ? ao.data() : nullptr,
    outputs >= 2 ? octants.data() : nullptr };
  double best = 1e300;
  for (int r = 0; r < repeat; ++r)
  {
    const auto start = std::chrono::steady_clock::now();
    const vao::Status status = vao::computeOcclusionSweeping(view, spacing, parameters, output);
    best = std::min(best, Seconds(start));
    if (!status.ok)
    {
      std::fprintf(stderr, "sweeping failed: %s\n", status.message.c_str());
      std::exit(1);
    }
  }
  return best;
}

void SweepRow(const std::string& label, const vao::VolumeView& view,
  const std::array<double, 3>& spacing, double iso, const std::string& rawForPeer,
  const Options& options)
{
  const size_t n = static_cast<size_t>(view.voxelCount());
  std::vector<float> distance(n), ao(n), octants(8 * n);
  const double sdf = TimeSweeping(view, spacing, iso, 0, options.repeat, distance, ao, octants);
  const double combined =
    TimeSweeping(view, spacing, iso, 1, options.repeat, distance, ao, octants);
  const double eight = TimeSweeping(view, spacing, iso, 2, options.repeat, distance, ao, octants);
  const EdtPeer edt = rawForPeer.empty() ? EdtPeer{} : RunScipyEdt(options, rawForPeer, iso);
  std::printf("  %-28s %10.0f %10.0f %10.0f %10.0f %10.0f %9.1fx\n", label.c_str(), 1e3 * sdf,
    1e3 * combined, 1e3 * eight, edt.unsignedSeconds > 0 ? 1e3 * edt.unsignedSeconds : -1.0,
    edt.signedSeconds > 0 ? 1e3 * edt.signedSeconds : -1.0,
    edt.signedSeconds > 0 ? edt.signedSeconds / eight : -1.0);
}

/// The sweeping table: the sizes of Singh et al.'s Table 2 (generated Fig. 3 scenes) and
/// the CT head phantom's skin.
void BenchmarkSweeping(const Options& options, vtkImageData* ct)
{
  std::printf("\nOcclusion sweeping (one pass; best of %d; ms) and "
              "scipy.ndimage.distance_transform_edt: unsigned\n"
              "  (one EDT) and signed (two EDTs and their difference, what SignedDistance holds); "
              "signed/8: the\n"
              "  signed EDT over the 8-octant sweep (issue 14's bar: at least 8x on 250^3)\n",
    options.repeat);
  std::printf("  %-28s %10s %10s %10s %10s %10s %10s\n", "volume", "SDF only", "SDF+AO",
    "8 octants", "scipy EDT", "signed EDT", "signed/8");
  const int sizes[][3] = { { 101, 101, 61 }, { 100, 100, 100 }, { 150, 150, 150 },
    { 200, 200, 200 }, { 250, 250, 250 } };
  for (const auto& size : sizes)
  {
    const int nx = size[0], ny = size[1], nz = size[2];
    const std::vector<float> volume = vaotest::SceneVolume(nx, ny, nz);
    const std::string raw = "/tmp/vao_sweep_" + std::to_string(nx) + "x" + std::to_string(ny) +
      "x" + std::to_string(nz) + "_float32.raw";
    std::ofstream(raw, std::ios::binary)
      .write(reinterpret_cast<const char*>(volume.data()), volume.size() * sizeof(float));
    vao::VolumeView view;
    view.data = volume.data();
    view.type = vao::ScalarType::Float32;
    view.dims = { nx, ny, nz };
    SweepRow(std::to_string(nx) + "x" + std::to_string(ny) + "x" + std::to_string(nz) + " scene",
      view, { 1.0, 1.0, 1.0 }, 0.5, raw, options);
    std::remove(raw.c_str());
  }
  vao::VolumeView view;
  view.data = ct->GetScalarPointer();
  view.type = vao::ScalarType::Int16;
  const int* d = ct->GetDimensions();
  view.dims = { d[0], d[1], d[2] };
  const double* h = ct->GetSpacing();
  // The peer reads float32: convert once for it.
  std::vector<float> asFloat(static_cast<size_t>(view.voxelCount()));
  const short* values = static_cast<const short*>(view.data);
  std::copy(values, values + asFloat.size(), asFloat.begin());
  const std::string raw = "/tmp/vao_sweep_ct_" + std::to_string(d[0]) + "x" + std::to_string(d[1]) +
    "x" + std::to_string(d[2]) + "_float32.raw";
  std::ofstream(raw, std::ios::binary)
    .write(reinterpret_cast<const char*>(asFloat.data()), asFloat.size() * sizeof(float));
  SweepRow("CT head skin (-300 HU)", view, { h[0], h[1], h[2] }, -300.0, raw, options);
  std::remove(raw.c_str());
}

} // namespace

int main(int argc, char* argv[])
{
  Options options;
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    if (arg == "--data" && i + 1 < argc)
      options.data = argv[++i];
    else if (arg == "--scipy" && i + 1 < argc)
      options.scipy = argv[++i];
    else if (arg == "--repeat" && i + 1 < argc)
      options.repeat = std::max(1, std::atoi(argv[++i]));
    else if (arg == "--threads" && i + 1 < argc)
      options.threads = std::max(0, std::atoi(argv[++i]));
    else if (arg == "--exact")
      options.exact = true;
    else if (arg == "--sweeping")
      options.sweepingOnly = true;
    else if (arg == "--penner")
      options.pennerOnly = true;
    else if (arg == "--relight")
      options.pennerOnly = options.relightOnly = true;
    else if (arg == "--volumetric")
      options.volumetricOnly = true;
    else if (arg == "--bytes")
    {
      BenchmarkBytes();
      return 0;
    }
    else if (arg == "--bytes-of" && i + 1 < argc)
      return RunBytesWorkload(argv[i + 1]);
    else
    {
      std::fprintf(stderr,
        "usage: %s [--data DIR] [--scipy FILE] [--repeat N] [--threads N] [--exact] [--volumetric "
        "| --sweeping | --penner | --relight | --bytes]\n",
        argv[0]);
      return 2;
    }
  }
  std::printf(
    "VolumetricAO benchmark: best of %d runs of the filter (wall clock, input in memory)\n",
    options.repeat);

  if (!options.sweepingOnly && !options.pennerOnly)
  {
    // The generated CT-body-sized volume, written raw for the scipy peer.
    vtkNew<vtkAmbientOcclusionPhantom> phantom;
    phantom->SetDimensions(256, 256, 415);
    phantom->Update();
    const std::string raw = "/tmp/vao_benchmark_phantom_256x256x415_int16.raw";
    std::ofstream(raw, std::ios::binary)
      .write(static_cast<const char*>(phantom->GetOutput()->GetScalarPointer()),
        phantom->GetOutput()->GetNumberOfPoints() * sizeof(short));
    Benchmark("generated phantom", phantom->GetOutput(), raw, options);
    std::remove(raw.c_str());

    const std::string ct =
      ScanPath(options.data, "ct_head_phantom/ct_head_phantom_512x512x209_int16.mha");
    Benchmark("ct_head_phantom_512x512x209_int16.mha", ReadScanOrExit(ct), ct, options);
  }
  if (options.volumetricOnly)
  {
    return 0;
  }
  const auto head =
    ReadScanOrExit(ScanPath(options.data, "ct_head_phantom/ct_head_phantom_128x128x136_int16.mha"));
  if (!options.pennerOnly)
  {
    BenchmarkSweeping(options, head);
  }
  if (!options.sweepingOnly)
  {
    if (!options.relightOnly)
      BenchmarkPyramid(options);
    std::printf("\nVariance occlusion maps: relighting, AO and soft shadows from a cached pyramid "
                "(best of %d)\n",
      options.repeat);
    BenchmarkRelighting(options, "CT head 128x128x136", head);
    BenchmarkRelighting(options, "CT head 512x512x209",
      ReadScanOrExit(
        ScanPath(options.data, "ct_head_phantom/ct_head_phantom_512x512x209_int16.mha")));
  }
  return 0;
}
