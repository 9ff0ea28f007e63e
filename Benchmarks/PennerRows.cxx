// The Penner & Mitchell tables of the benchmark: the pyramid build against its floor and
// scipy's level-0 blur, and the surface query rates (AO, soft shadows) on a CT head's bone
// surface once the pyramid is cached.
#include "PennerRows.h"

#include "vtkAmbientOcclusionPhantom.h"
#include "vtkFlyingEdges3D.h"
#include "vtkImageData.h"
#include "vtkNew.h"
#include "vtkPointData.h"
#include "vtkPolyData.h"

#include "vao/Storage.h"
#include "vao/VarianceOcclusionMap.h"

#include <array>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <thread>
#include <utility>
#include <vector>

namespace vaobench
{
namespace
{

/// The floor of a pyramid build: one pass, on the same threads, that reads the int16
/// volume once and writes as many floats as the levels hold (mean and variance of each)
/// into arrays kept from one repeat to the next, as the pyramid's storage is.
double TimePyramidFloor(const short* in, std::int64_t n,
  const std::vector<vao::MomentLevel>& levels, int repeat, int threads)
{
  std::int64_t coarse = 0; // voxels of the levels after the first
  for (std::size_t l = 1; l < levels.size(); ++l)
    coarse += levels[l].dims[0] * levels[l].dims[1] * levels[l].dims[2];
  std::vector<float> mean(static_cast<std::size_t>(n)), variance(mean.size());
  std::vector<float> coarseMean(static_cast<std::size_t>(coarse)),
    coarseVariance(coarseMean.size());
  const int team = ResolvedThreads(threads);
  double best = 1e300;
  for (int r = 0; r < repeat; ++r)
  {
    const auto start = std::chrono::steady_clock::now();
    std::vector<std::thread> workers;
    for (int t = 0; t < team; ++t)
    {
      workers.emplace_back(
        [&, t]
        {
          const std::int64_t begin = n * t / team, end = n * (t + 1) / team;
          for (std::int64_t i = begin; i < end; ++i)
          {
            const float v = static_cast<float>(in[i]);
            mean[i] = v;
            variance[i] = v * v;
            if (i < coarse)
            {
              coarseMean[i] = v;
              coarseVariance[i] = v * v;
            }
          }
        });
    }
    for (auto& w : workers)
      w.join();
    best = std::min(best, Seconds(start));
  }
  return best;
}

/// The build as the filter runs it, into new levels whose blocks become its output arrays:
/// best seconds into blocks fresh from the system (an output freed with freeStorage before)
/// and into blocks an earlier output left (freed with recycleStorage, as the filter's
/// arrays are), alternating so that both see the same spells of this machine.
std::pair<double, double> TimeFreshAndRecycledBuilds(
  const vao::VolumeView& view, const vao::Execution& execution, int repeat)
{
  double best[2] = { 1e300, 1e300 };
  vao::releaseKeptStorage();
  bool recycled = false; // how the previous build's blocks were freed
  for (int r = 0; r < 2 * repeat + 1; ++r)
  {
    std::vector<vao::MomentLevel> pyramid;
    const auto start = std::chrono::steady_clock::now();
    vao::buildMomentPyramid(view, { 0, 0, 0 }, { 1, 1, 1 }, {}, pyramid, execution);
    const double seconds = Seconds(start);
    if (r > 0) // the first build's blocks are new either way
      best[recycled] = std::min(best[recycled], seconds);
    recycled = r % 2 == 0;
    for (auto& level : pyramid)
      for (auto* values : { &level.mean, &level.variance })
        (recycled ? vao::recycleStorage : vao::freeStorage)(values->release());
    if (!recycled)
      vao::releaseKeptStorage();
  }
  vao::releaseKeptStorage();
  return { best[0], best[1] };
}

/// scipy.ndimage's level-0 blur of v and v^2 on a raw volume (scipy_blur_peer.py);
/// seconds, or a negative value when it cannot run.
double RunScipyBlur(const Options& options, const std::string& volumeFile)
{
  const std::string command = "/usr/bin/python3 '" + options.scipyBlur + "' '" + volumeFile + "'";
  FILE* pipe = popen(command.c_str(), "r");
  if (!pipe)
    return -1.0;
  char line[256];
  double seconds = -1.0;
  while (std::fgets(line, sizeof(line), pipe))
    if (std::sscanf(line, "scipy_blur %lf", &seconds) == 1)
      break;
  pclose(pipe);
  return seconds;
}

} // namespace

/// Penner & Mitchell: the pyramid build on generated volumes of the paper's Table 1 sizes,
/// each against its floor, and on 256^3 against scipy.ndimage's level-0 blur.
void BenchmarkPyramid(const Options& options)
{
  std::printf("\nVariance occlusion maps: pyramid build (4 levels, best of %d, ms; paper Table 1: "
              "170 / 678 / "
              "1524 ms CPU); the floor reads the volume once and writes the levels' floats once\n",
    options.repeat);
  std::printf(
    "  %-22s %8s %10s %8s %14s\n", "volume", "build", "floor", "x floor", "scipy level 0");
  const int sizes[][3] = { { 256, 256, 256 }, { 512, 512, 256 }, { 512, 512, 512 } };
  for (const auto& size : sizes)
  {
    vtkNew<vtkAmbientOcclusionPhantom> phantom;
    phantom->SetDimensions(size[0], size[1], size[2]);
    phantom->Update();
    vao::VolumeView view;
    view.data = phantom->GetOutput()->GetScalarPointer();
    view.type = vao::ScalarType::Int16;
    view.dims = { size[0], size[1], size[2] };
    vao::Execution execution;
    execution.threads = options.threads;
    std::vector<vao::MomentLevel> pyramid;
    double best = 1e300;
    for (int r = 0; r < options.repeat; ++r)
    {
      const auto start = std::chrono::steady_clock::now();
      vao::buildMomentPyramid(view, { 0, 0, 0 }, { 1, 1, 1 }, {}, pyramid, execution);
      best = std::min(best, Seconds(start));
    }
    const double floor = TimePyramidFloor(static_cast<const short*>(view.data), view.voxelCount(),
      pyramid, std::max(3, options.repeat), options.threads);
    std::printf("  %4d x %4d x %4d int16 %8.1f %10.1f %7.1fx", size[0], size[1], size[2],
      1e3 * best, 1e3 * floor, best / floor);
    if (size[2] == 256 && size[0] == 256)
    {
      const std::string raw = "/tmp/vao_pyramid_256x256x256_int16.raw";
      std::ofstream(raw, std::ios::binary)
        .write(
          static_cast<const char*>(view.data), static_cast<std::streamsize>(2 * view.voxelCount()));
      const double peer = RunScipyBlur(options, raw);
      std::remove(raw.c_str());
      if (peer > 0)
        std::printf(
          " %9.1f: ours %.1fx faster, the floor %.1fx", 1e3 * peer, peer / best, peer / floor);
      else
        std::printf("   (scipy blur peer could not run)");
      const auto builds = TimeFreshAndRecycledBuilds(view, execution, options.repeat);
      std::printf("\n  %-22s into new blocks (a first run) %.1f ms, into an earlier output's "
                  "(vao::recycleStorage) %.1f ms",
        "", 1e3 * builds.first, 1e3 * builds.second);
    }
    std::printf("\n");
  }
}

/// The surface query rates (what a light move costs once the pyramid is cached) on the
/// bone surface (400 HU) of a CT head: default parameters, light (0, -1, 1).
void BenchmarkRelighting(const Options& options, const char* name, vtkImageData* ct)
{
  vtkNew<vtkFlyingEdges3D> contour;
  contour->SetInputData(ct);
  contour->SetValue(0, 400.0);
  contour->ComputeNormalsOn();
  contour->Update();
  vtkPolyData* bone = contour->GetOutput();
  const vtkIdType n = bone->GetNumberOfPoints();
  std::vector<double> points(3 * n), normals(3 * n);
  for (vtkIdType i = 0; i < n; ++i)
  {
    bone->GetPoint(i, &points[3 * i]);
    bone->GetPointData()->GetNormals()->GetTuple(i, &normals[3 * i]);
  }
  vao::VolumeView view;
  view.data = ct->GetScalarPointer();
  view.type = vao::ScalarType::Int16;
  const int* d = ct->GetDimensions();
  view.dims = { d[0], d[1], d[2] };
  const double* o = ct->GetOrigin();
  const double* h = ct->GetSpacing();
  const std::array<double, 3> origin = { o[0], o[1], o[2] }, spacing = { h[0], h[1], h[2] };
  vao::Execution execution;
  execution.threads = options.threads;
  std::vector<vao::MomentLevel> pyramid;
  vao::buildMomentPyramid(view, origin, spacing, {}, pyramid, execution);
  vao::SurfacePyramid surface; // what the filter keeps: levels 0 and 1 in the tiles reached
  vao::buildSurfacePyramid(view, origin, spacing, {}, surface, execution);
  std::vector<float> ao(n), shadow(n);
  const std::array<double, 3> light = { 0.0, -1.0, 1.0 };
  // AO and shadows of a new surface on the SurfacePyramid in one pass, as the filter
  // computes them.
  auto onePass = [&]
  {
    vao::surfaceOcclusionAndShadow(surface, view, origin, spacing, points.data(), normals.data(), n,
      light, {}, ao.data(), shadow.data(), execution);
  };
  // The best of `repeat` runs of AO, shadows or both, on either pyramid, in M points/s.
  auto rate = [&](bool tiled, bool occlusion, bool shadows)
  {
    double best = 1e300;
    for (int r = 0; r < options.repeat; ++r)
    {
      const auto start = std::chrono::steady_clock::now();
      if (tiled && occlusion && shadows)
        onePass();
      else
      {
        if (occlusion)
          tiled ? vao::surfaceAmbientOcclusion(surface, view, origin, spacing, points.data(),
                    normals.data(), n, {}, ao.data(), execution)
                : vao::surfaceAmbientOcclusion(pyramid, view, origin, spacing, points.data(),
                    normals.data(), n, {}, ao.data(), execution);
        if (shadows)
          tiled ? vao::surfaceShadow(
                    surface, points.data(), normals.data(), n, light, {}, shadow.data(), execution)
                : vao::surfaceShadow(
                    pyramid, points.data(), normals.data(), n, light, {}, shadow.data(), execution);
      }
      best = std::min(best, Seconds(start));
    }
    return n / best / 1e6;
  };
  // The first query on a fresh SurfacePyramid builds its tiles; with the build, what a new
  // volume costs.
  double first = 1e300, withBuild = 1e300;
  for (int r = 0; r < options.repeat; ++r)
  {
    const auto built = std::chrono::steady_clock::now();
    vao::buildSurfacePyramid(view, origin, spacing, {}, surface, execution);
    const auto start = std::chrono::steady_clock::now();
    onePass();
    first = std::min(first, Seconds(start));
    withBuild = std::min(withBuild, Seconds(built));
  }
  std::printf(
    "  %s bone surface (400 HU, %lld points), M points/s:\n", name, static_cast<long long>(n));
  std::printf("    whole pyramid:     AO %.1f, shadows %.1f, AO + shadows %.1f\n",
    rate(false, true, false), rate(false, false, true), rate(false, true, true));
  std::printf("    surface pyramid:   AO %.1f, shadows %.1f, AO + shadows %.1f (%.1f the first "
              "time, %.1f with the pyramid's build; tiles built: "
              "%.1f%% of level 0, %.1f%% of level 1)\n",
    rate(true, true, false), rate(true, false, true), rate(true, true, true), n / first / 1e6,
    n / withBuild / 1e6, 100.0 * surface.builtTiles(0) / surface.tileCount(0),
    100.0 * surface.builtTiles(1) / surface.tileCount(1));
  // With every tile the surface reaches kept, a query samples just what the whole
  // pyramid's does: the gap between the rows above is the tiles the default budget
  // rebuilds, and the first query's gap is the tiles it builds.
  const double inputBytes = static_cast<double>(sizeof(short) * view.voxelCount());
  const double budget = static_cast<double>(surface.keptTileBytes());
  surface.setKeptTileBytes(static_cast<std::size_t>(-1));
  onePass();
  std::printf("    every tile kept:   AO + shadows %.1f (%lld tiles of level 0 and %lld of level "
              "1, %.1f MB, %.0f%% of the input's bytes; the default keeps %.0f%%)\n",
    rate(true, true, true), static_cast<long long>(surface.builtTiles(0)),
    static_cast<long long>(surface.builtTiles(1)), surface.tileMemory() / 1e6,
    100.0 * static_cast<double>(surface.tileMemory()) / inputBytes, 100.0 * budget / inputBytes);
}

} // namespace vaobench
