// Benchmark: the filter's time for each method at R = 5 and 10 on a 256x256x415 volume
// (the CT-body size of Ruiz et al. Table 1) and on the 512x512x209 CT head phantom, and,
// measured in the same run, scipy.ndimage computing the same statistics.
//
// Usage: vao_benchmark [--shared DIR] [--scipy PATH/TO/scipy_peer.py] [--repeat N]
//                      [--exact] [--threads N]
// Exact Box and Exact Sphere are O(R^3) references: by default they are timed on a
// 32-slice slab and the whole-volume time is extrapolated (marked "~"); --exact times
// them on the whole volume (minutes).
#include "vtkAmbientOcclusionPhantom.h"
#include "vtkVolumetricAmbientOcclusion.h"

#include "vao/AmbientOcclusion.h"

#include "vtkExtractVOI.h"
#include "vtkImageData.h"
#include "vtkMetaImageReader.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkSmartPointer.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

namespace
{

int ResolvedThreads(int requested)
{
  return requested > 0 ? requested : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

double Seconds(const std::chrono::steady_clock::time_point& start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

struct Options
{
  std::string shared = VAO_DEFAULT_SHARED_DATA_DIR;
  std::string scipy = VAO_DEFAULT_SCIPY_PEER;
  int repeat = 3;
  bool exact = false;
  int threads = 0;
};

/// Best of `repeat` wall-clock times of one filter update on an in-memory image.
double TimeFilter(vtkImageData* image, int method, int radius, int repeat, int threads)
{
  double best = 1e300;
  for (int r = 0; r < repeat; ++r)
  {
    vtkNew<vtkVolumetricAmbientOcclusion> filter;
    filter->SetInputData(image);
    filter->SetMethod(method);
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
  std::printf("  %-20s %12s %12s\n", "method", "R = 5 [ms]", "R = 10 [ms]");
  const char* names[] = { "CDF Reconstruction", "Gaussian CDF", "Chebyshev", "Exact Box", "Exact Sphere" };
  for (int method = 0; method < 5; ++method)
  {
    std::printf("  %-20s", names[method]);
    for (int radius : { 5, 10 })
    {
      const bool reference = method >= vtkVolumetricAmbientOcclusion::EXACT_BOX;
      if (reference && !options.exact)
      {
        // A 32-slice slab, extrapolated by voxel count (the cost is uniform per voxel).
        vtkNew<vtkExtractVOI> slab;
        slab->SetInputData(image);
        const int* e = image->GetExtent();
        slab->SetVOI(e[0], e[1], e[2], e[3], e[4], e[4] + 31);
        slab->Update();
        const double t = TimeFilter(slab->GetOutput(), method, radius, 1, options.threads);
        std::printf(" %11.0f~", 1e3 * t * voxels / slab->GetOutput()->GetNumberOfPoints());
      }
      else
      {
        std::printf(" %12.1f", 1e3 * TimeFilter(image, method, radius, options.repeat, options.threads));
      }
      std::fflush(stdout);
    }
    std::printf("\n");
  }
  const double stats5 = TimeStatistics(image, 5, options.repeat, options.threads);
  const double stats10 = TimeStatistics(image, 10, options.repeat, options.threads);
  std::printf("  %-20s %12.1f %12.1f\n", "statistics (ours)", 1e3 * stats5, 1e3 * stats10);
  const auto scipy = RunScipy(options, scipyFile);
  if (scipy.size() == 2)
  {
    std::printf("  %-20s %12.1f %12.1f\n", "scipy.ndimage", 1e3 * scipy.at(5), 1e3 * scipy.at(10));
    std::printf("  %-20s %11.1fx %11.1fx\n", "speed-up", scipy.at(5) / stats5, scipy.at(10) / stats10);
  }
  else
  {
    std::printf("  scipy.ndimage: could not run %s (python3-scipy missing?)\n", options.scipy.c_str());
  }
}

} // namespace

int main(int argc, char* argv[])
{
  Options options;
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    if (arg == "--shared" && i + 1 < argc)
      options.shared = argv[++i];
    else if (arg == "--scipy" && i + 1 < argc)
      options.scipy = argv[++i];
    else if (arg == "--repeat" && i + 1 < argc)
      options.repeat = std::max(1, std::atoi(argv[++i]));
    else if (arg == "--threads" && i + 1 < argc)
      options.threads = std::max(0, std::atoi(argv[++i]));
    else if (arg == "--exact")
      options.exact = true;
    else
    {
      std::fprintf(stderr, "usage: %s [--shared DIR] [--scipy FILE] [--repeat N] [--threads N] [--exact]\n", argv[0]);
      return 2;
    }
  }
  std::printf("VolumetricAO benchmark: best of %d runs of the filter (wall clock, input in memory)\n",
    options.repeat);

  // The generated CT-body-sized volume, written raw for the scipy peer.
  vtkNew<vtkAmbientOcclusionPhantom> phantom;
  phantom->SetDimensions(256, 256, 415);
  phantom->Update();
  const std::string raw = "/tmp/vao_benchmark_phantom_256x256x415_int16.raw";
  {
    std::ofstream out(raw, std::ios::binary);
    out.write(static_cast<const char*>(phantom->GetOutput()->GetScalarPointer()),
      phantom->GetOutput()->GetNumberOfPoints() * sizeof(short));
  }
  Benchmark("generated phantom", phantom->GetOutput(), raw, options);
  std::remove(raw.c_str());

  const std::string ct = options.shared + "/ct_head_phantom/ct_head_phantom_512x512x209_int16.mha";
  vtkNew<vtkMetaImageReader> reader;
  reader->SetFileName(ct.c_str());
  reader->Update();
  if (reader->GetOutput()->GetNumberOfPoints() == 0)
  {
    std::fprintf(stderr, "cannot read %s\n", ct.c_str());
    return 1;
  }
  Benchmark("ct_head_phantom_512x512x209_int16.mha", reader->GetOutput(), ct, options);
  return 0;
}
