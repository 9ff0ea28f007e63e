// GPU benchmark of the CUDA backend (vao::cuda, CUDA/include/vao/Cuda.h): kernel and
// end-to-end times of the Gaussian CDF openness and of the five box statistics (and of
// Histogram CDF and Exact Box, CountingRows.h; and the pyramid, PyramidRow.h), the CPU
// time of the same calls for reference, the effective bandwidth of every device pass
// against the device's copy bandwidth, and, measured in the same run, cupyx.scipy.ndimage
// computing the same statistics (cupy_peer.py). It checks the bars of the issue and prints
// one PASS/FAIL line for each.
//
// Usage: vao_gpu_benchmark [--quick] [--repeat N] [--cpu-all] [--strict]
//                          [--cupy PATH/TO/cupy_peer.py] [--python EXE] [--no-cupy]
//                          [--raw-dir DIR] [--keep-raw]
//   --quick    only the 256x256x113 volumes
//   --repeat   timed runs after one warm-up, best reported (default 5)
//   --cpu-all  also time the CPU on 512^3 (skipped by default: seconds per call)
//   --strict   exit 1 when a bar fails (default: report only; exit 1 only on errors)
// Without a device it prints "no CUDA device: <why>" and exits 0.
#include "vao/AmbientOcclusion.h"
#include "vao/Cuda.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdarg>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <type_traits>
#include <vector>

#include "CountingRows.h"
#include "GpuBenchmarkSupport.h"
#include "PyramidRow.h"

#ifndef VAO_DEFAULT_CUPY_PEER
#define VAO_DEFAULT_CUPY_PEER "cupy_peer.py"
#endif

namespace
{

using namespace gpubench;

struct Options
{
  bool quick = false;
  int repeat = 5;
  bool cpuAll = false;
  bool strict = false;
  bool cupy = true;
  bool keepRaw = false;
  std::string cupyPeer = VAO_DEFAULT_CUPY_PEER;
  std::string python = "python3";
  std::string rawDir = "/tmp";
};

// ---------------------------------------------------------------------------------------
// The generated volume: a smooth CT-like body (air, fat, soft tissue, lungs, spine, ribs,
// vessels) in Hounsfield units, plus deterministic noise.

std::uint64_t splitmix64(std::uint64_t x)
{
  x += 0x9e3779b97f4a7c15ULL;
  x = (x ^ (x >> 30)) * 0xbf58476d1ce4e5b9ULL;
  x = (x ^ (x >> 27)) * 0x94d049bb133111ebULL;
  return x ^ (x >> 31);
}

/// Uniform in [-1, 1), a pure function of the voxel index.
double noiseAt(std::uint64_t index)
{
  return static_cast<double>(splitmix64(index) >> 11) * (2.0 / 9007199254740992.0) - 1.0;
}

double ctValue(double u, double v, double w)
{
  // u, v, w in [-1, 1]: x (left-right), y (front-back), z (feet-head).
  const double body = (u / 0.85) * (u / 0.85) + (v / 0.62) * (v / 0.62);
  if (body > 1.0)
  {
    return -1000.0; // air
  }
  double value = 40.0 + 15.0 * std::sin(3.0 * u + 2.0 * w) * std::cos(4.0 * v); // soft tissue
  if (body > 0.85)
  {
    value = -90.0; // subcutaneous fat
  }
  if (body > 0.72 && body < 0.78 && std::sin(18.0 * w + 0.5 * u) > 0.35)
  {
    value = 450.0 + 150.0 * std::cos(7.0 * u); // ribs
  }
  for (double side : { -1.0, 1.0 })
  {
    const double lu = (u - side * 0.38) / 0.26, lv = (v + 0.05) / 0.36, lw = (w - 0.3) / 0.65;
    if (lu * lu + lv * lv + lw * lw < 1.0)
    {
      value = -840.0 + 60.0 * std::sin(11.0 * u * v + 5.0 * w); // lungs
    }
  }
  const double su = u / 0.09, sv = (v - 0.42) / 0.09;
  if (su * su + sv * sv < 1.0)
  {
    value = std::sin(12.0 * w) > -0.6 ? 750.0 + 200.0 * (1.0 - su * su - sv * sv)
                                      : 60.0; // vertebrae, discs
  }
  const double au = (u + 0.08) / 0.05, av = (v - 0.22) / 0.05;
  if (au * au + av * av < 1.0)
  {
    value = 280.0; // contrast-filled aorta
  }
  return value;
}

template <class T>
std::vector<T> generateVolume(const vao::Index3& dims)
{
  const std::int64_t nx = dims[0], ny = dims[1], nz = dims[2];
  std::vector<T> volume(static_cast<std::size_t>(nx * ny * nz));
  const unsigned workers = std::max(1u, std::thread::hardware_concurrency());
  std::vector<std::thread> threads;
  for (unsigned t = 0; t < workers; ++t)
  {
    threads.emplace_back(
      [&, t]
      {
        for (std::int64_t z = t; z < nz; z += workers)
          for (std::int64_t y = 0; y < ny; ++y)
            for (std::int64_t x = 0; x < nx; ++x)
            {
              const std::int64_t i = (z * ny + y) * nx + x;
              const double u = 2.0 * (x + 0.5) / nx - 1.0, v = 2.0 * (y + 0.5) / ny - 1.0,
                           w = 2.0 * (z + 0.5) / nz - 1.0;
              const double value = ctValue(u, v, w) + 25.0 * noiseAt(static_cast<std::uint64_t>(i));
              volume[static_cast<std::size_t>(i)] =
                static_cast<T>(std::is_integral<T>::value ? std::lround(value) : value);
            }
      });
  }
  for (auto& thread : threads)
  {
    thread.join();
  }
  return volume;
}

/// Effective bandwidth of every pass, with its share of the copy bandwidth; one bar.
void reportPasses(const std::string& what, const GpuTimes& times, double copyGBs)
{
  std::printf("    passes of %s (run with the best kernel time):\n", what.c_str());
  std::printf("      %-28s %9s %10s %9s %8s\n", "pass", "ms", "MB", "GB/s", "% copy");
  double worstShare = 1e300;
  std::string worstName;
  for (const auto& pass : times.passes)
  {
    const double gbs = pass.milliseconds > 0 ? pass.bytes / (pass.milliseconds * 1e6) : 0.0;
    const double share = copyGBs > 0 ? 100.0 * gbs / copyGBs : 0.0;
    std::printf("      %-28s %9.3f %10.1f %9.1f %7.1f%%\n", pass.name.c_str(), pass.milliseconds,
      pass.bytes / 1e6, gbs, share);
    if (share < worstShare)
    {
      worstShare = share;
      worstName = pass.name;
    }
  }
  if (times.uploadGBs > 0 || times.downloadGBs > 0)
  {
    std::printf(
      "      transfers (z slabs, pinned staging, overlapped): up %.1f GB/s, down %.1f GB/s\n",
      times.uploadGBs, times.downloadGBs);
  }
  if (times.passes.empty())
  {
    bar("FAIL", what + ": every pass >= 50% of copy bandwidth: no passes reported in Timing");
  }
  else
  {
    bar(worstShare >= 50.0 ? "PASS" : "FAIL",
      format("%s: every pass >= 50%% of copy bandwidth (worst: %s at %.1f%% of %.0f GB/s)",
        what.c_str(), worstName.c_str(), worstShare, copyGBs));
  }
}

// ---------------------------------------------------------------------------------------
// The cupy peer.

struct CupyResult
{
  std::map<int, double> milliseconds; // per radius
  std::string problem;                // why there are none
};

CupyResult runCupy(const Options& options, const std::string& rawFile, const std::string& label,
  const std::vector<int>& radii)
{
  CupyResult result;
  std::string command = "'" + options.python + "' '" + options.cupyPeer + "' '" + rawFile + "'";
  for (int r : radii)
  {
    command += " " + std::to_string(r);
  }
  command += " --repeat " + std::to_string(options.repeat) + " 2>&1";
  std::fflush(stdout);
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe)
  {
    result.problem = "cannot run " + command;
    return result;
  }
  char line[4096];
  while (std::fgets(line, sizeof(line), pipe))
  {
    char got[256];
    int radius = 0;
    double ms = 0;
    if (std::sscanf(line, "cupy %255s %d %lf", got, &radius, &ms) == 3 && label == got)
    {
      result.milliseconds[radius] = ms;
    }
    else
    {
      std::printf("    [cupy_peer] %s", line); // "cupy not available: ...", errors
      std::string text = line;
      if (!text.empty() && text.back() == '\n')
      {
        text.pop_back();
      }
      if (result.problem.empty() && !text.empty())
      {
        result.problem = text;
      }
    }
  }
  const int rc = pclose(pipe);
  if (rc != 0 && result.problem.empty())
  {
    result.problem = format("%s exited with status %d", options.cupyPeer.c_str(), rc);
  }
  return result;
}

// ---------------------------------------------------------------------------------------

template <class T>
void benchmarkVolume(const Options& options, const vao::Index3& dims, const char* typeName)
{
  const std::int64_t n = dims[0] * dims[1] * dims[2];
  const std::string label = format("%lldx%lldx%lld_%s", static_cast<long long>(dims[0]),
    static_cast<long long>(dims[1]), static_cast<long long>(dims[2]), typeName);
  const bool large = n > 256LL * 256 * 415;
  const bool runCpu = !large || options.cpuAll;

  const auto generateStart = std::chrono::steady_clock::now();
  const std::vector<T> volume = generateVolume<T>(dims);
  vao::VolumeView view;
  view.data = volume.data();
  view.type = std::is_same<T, float>::value ? vao::ScalarType::Float32 : vao::ScalarType::Int16;
  view.dims = dims;
  const vao::Region whole = vao::Region::whole(view);
  const double copyBytes = static_cast<double>(n) * sizeof(float) * 2;
  const double copyGBs = vao::cuda::measureCopyBandwidth(copyBytes);
  std::printf("\n== %s (%.1f M voxels, generated in %.0f ms); copy bandwidth %.0f GB/s "
              "(measureCopyBandwidth of %.0f MB)\n",
    label.c_str(), n / 1e6, millisecondsSince(generateStart), copyGBs, copyBytes / 1e6);

  std::vector<float> openness(n), cpuOpenness(runCpu ? n : 0);
  std::vector<double> count(n), mean(n), variance(n), minimum(n), maximum(n);
  const vao::BoxStatisticsOutput statsOutput{ count.data(), mean.data(), variance.data(),
    minimum.data(), maximum.data() };
  const int cpuRepeat = std::min(options.repeat, 3);
  const std::vector<int> radii = { 5, 10 };
  std::map<int, double> statsKernelMs, aoKernelMs;

  std::printf("  %-26s %3s %12s %15s %10s %12s\n", "call", "R", "kernels[ms]", "end-to-end[ms]",
    "CPU[ms]", "CPU/kernels");
  for (int radius : radii)
  {
    vao::AmbientOcclusionParameters p;
    p.method = vao::Method::GaussianCdf;
    p.erfMode = vao::ErfMode::Exact;
    p.radius = { radius, radius, radius };
    const GpuTimes ao = timeGpu(
      [&](vao::cuda::Timing* t) {
        return vao::cuda::computeAmbientOcclusion(
          view, whole, p, { openness.data(), nullptr }, {}, t);
      },
      options.repeat);
    const GpuTimes stats = timeGpu([&](vao::cuda::Timing* t)
      { return vao::cuda::computeBoxStatistics(view, whole, p.radius, statsOutput, {}, t); },
      options.repeat);
    double cpuAo = -1, cpuStats = -1;
    if (runCpu)
    {
      cpuAo = timeCpu(
        [&] {
          return vao::computeAmbientOcclusion(view, whole, p, { cpuOpenness.data(), nullptr });
        },
        cpuRepeat);
    }
    if (runCpu && stats.ok)
    {
      // Into the same arrays: the GPU's statistics are not needed any more.
      cpuStats = timeCpu(
        [&] { return vao::computeBoxStatistics(view, whole, p.radius, statsOutput); }, cpuRepeat);
    }

    struct Row
    {
      const char* name;
      const GpuTimes& gpu;
      double cpu;
    };
    for (const Row& row : { Row{ "Gaussian CDF openness", ao, cpuAo },
           Row{ "box statistics (5 outputs)", stats, cpuStats } })
    {
      if (!row.gpu.ok)
      {
        std::printf(
          "  %-26s %3d  GPU call failed: %s\n", row.name, radius, row.gpu.message.c_str());
        callFailed = true;
        continue;
      }
      std::printf("  %-26s %3d %12.3f %15.3f", row.name, radius, row.gpu.kernelMs, row.gpu.totalMs);
      if (row.cpu >= 0)
        std::printf(" %10.1f %11.1fx\n", row.cpu, row.cpu / row.gpu.kernelMs);
      else
        std::printf(" %10s %12s\n", runCpu ? "failed" : "skipped", "");
    }
    if (ao.ok && runCpu && cpuAo >= 0)
    {
      double worst = 0;
      for (std::int64_t i = 0; i < n; ++i)
      {
        worst = std::max(worst, static_cast<double>(std::abs(openness[i] - cpuOpenness[i])));
      }
      std::printf("    max |GPU - CPU| Gaussian CDF openness: %.3g\n", worst);
      if (worst > 1e-5)
      {
        bar("FAIL",
          format("%s R=%d: GPU openness equals the CPU's to 1e-5 (max difference %.3g)",
            label.c_str(), radius, worst));
      }
    }
    if (ao.ok)
    {
      reportPasses(format("%s R=%d Gaussian CDF", label.c_str(), radius), ao, copyGBs);
      aoKernelMs[radius] = ao.kernelMs;
    }
    if (stats.ok)
    {
      reportPasses(format("%s R=%d box statistics", label.c_str(), radius), stats, copyGBs);
      statsKernelMs[radius] = stats.kernelMs;
    }
    if (dims[0] == 256 && dims[1] == 256 && dims[2] == 415 && radius == 10)
    {
      if (ao.ok)
      {
        bar(ao.kernelMs <= 0.5 ? "PASS" : "FAIL",
          format("%s R=10 Gaussian CDF kernels %.3f ms <= 0.5 ms", label.c_str(), ao.kernelMs));
        bar(ao.totalMs <= 8.0 ? "PASS" : "FAIL",
          format("%s R=10 Gaussian CDF end-to-end %.3f ms <= 8 ms", label.c_str(), ao.totalMs));
      }
      else
      {
        bar("FAIL", label + " R=10 Gaussian CDF: the GPU call failed: " + ao.message);
      }
    }
  }

  const auto gaussian10 = aoKernelMs.find(10);
  benchmarkCounting(view, label, options.repeat,
    gaussian10 == aoKernelMs.end() ? -1.0 : gaussian10->second,
    dims[0] == 256 && dims[1] == 256 && dims[2] == 415 && !std::is_same<T, float>::value);

  // The peer: cupyx.scipy.ndimage on the same voxels, read back from a raw file.
  if (!options.cupy)
  {
    return;
  }
  const std::string raw = options.rawDir + "/vao_gpu_" + label + ".raw";
  {
    std::ofstream out(raw, std::ios::binary);
    out.write(
      reinterpret_cast<const char*>(volume.data()), static_cast<std::streamsize>(n * sizeof(T)));
    if (!out)
    {
      std::printf("  cannot write %s: no cupy comparison\n", raw.c_str());
      bar("SKIP", label + ": speed-up vs cupy (cannot write the raw file)");
      return;
    }
  }
  const CupyResult cupy = runCupy(options, raw, label, radii);
  if (!options.keepRaw)
  {
    std::remove(raw.c_str());
  }
  for (int radius : radii)
  {
    const auto it = cupy.milliseconds.find(radius);
    const auto ours = statsKernelMs.find(radius);
    if (it == cupy.milliseconds.end() || ours == statsKernelMs.end())
    {
      bar("SKIP",
        format("%s R=%d speed-up of box statistics kernels vs cupy >= 10x: %s", label.c_str(),
          radius, ours == statsKernelMs.end() ? "our call failed" : cupy.problem.c_str()));
      continue;
    }
    const double speedUp = it->second / ours->second;
    std::printf("  cupyx.scipy.ndimage R=%d: %.3f ms (uniform x2 float64 + minimum + maximum); "
                "ours %.3f ms\n",
      radius, it->second, ours->second);
    bar(speedUp >= 10.0 ? "PASS" : "FAIL",
      format("%s R=%d speed-up of box statistics kernels vs cupy %.1fx >= 10x", label.c_str(),
        radius, speedUp));
  }
}

} // namespace

int main(int argc, char* argv[])
{
  Options options;
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    if (arg == "--quick")
      options.quick = true;
    else if (arg == "--repeat" && i + 1 < argc)
      options.repeat = std::max(1, std::atoi(argv[++i]));
    else if (arg == "--cpu-all")
      options.cpuAll = true;
    else if (arg == "--strict")
      options.strict = true;
    else if (arg == "--cupy" && i + 1 < argc)
      options.cupyPeer = argv[++i];
    else if (arg == "--python" && i + 1 < argc)
      options.python = argv[++i];
    else if (arg == "--no-cupy")
      options.cupy = false;
    else if (arg == "--raw-dir" && i + 1 < argc)
      options.rawDir = argv[++i];
    else if (arg == "--keep-raw")
      options.keepRaw = true;
    else
    {
      std::fprintf(stderr,
        "usage: %s [--quick] [--repeat N] [--cpu-all] [--strict] [--cupy PEER.py] [--python EXE] "
        "[--no-cupy] [--raw-dir DIR] [--keep-raw]\n",
        argv[0]);
      return 2;
    }
  }

  const vao::cuda::DeviceStatus device = vao::cuda::deviceStatus();
  if (!device.available)
  {
    std::printf("no CUDA device: %s (CUDA backend built: %s)\n", device.description.c_str(),
      vao::cuda::built() ? "yes" : "no");
    return 0;
  }
  std::printf("VolumetricAO GPU benchmark on %s\n", device.description.c_str());
  std::printf(
    "best of %d runs after one warm-up (CPU: best of %d, %u threads); kernels: CUDA events; "
    "end-to-end: the whole call (allocation, transfers, kernels)\n",
    options.repeat, std::min(options.repeat, 3), std::max(1u, std::thread::hardware_concurrency()));

  std::vector<vao::Index3> sizes = { { 256, 256, 113 } };
  if (!options.quick)
  {
    sizes.push_back({ 256, 256, 415 });
    sizes.push_back({ 512, 512, 512 });
  }
  for (const auto& dims : sizes)
  {
    benchmarkVolume<float>(options, dims, "float32");
    benchmarkVolume<std::int16_t>(options, dims, "int16");
  }

  const vao::Index3 cube = { 256, 256, 256 };
  benchmarkPyramid(generateVolume<std::int16_t>(cube), cube, options.repeat);

  int passed = 0, failed = 0, skipped = 0;
  std::printf("\nBars of the issue:\n");
  for (const Bar& b : bars)
  {
    std::printf("  %s %s\n", b.verdict.c_str(), b.text.c_str());
    (b.verdict == "PASS" ? passed : b.verdict == "FAIL" ? failed : skipped)++;
  }
  std::printf("bars: %d passed, %d failed, %d skipped%s\n", passed, failed, skipped,
    callFailed ? "; some GPU calls FAILED" : "");
  if (callFailed)
  {
    return 1;
  }
  return options.strict && failed > 0 ? 1 : 0;
}
