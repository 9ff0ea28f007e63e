// What the GPU benchmark's rows share: timing of device and CPU calls, the PASS/FAIL/SKIP
// bars of the issue, and printf-style formatting. Included by vao_gpu_benchmark.cxx only.
#pragma once

#include "vao/Cuda.h"

#include <algorithm>
#include <chrono>
#include <cstdarg>
#include <cstdio>
#include <string>
#include <vector>

namespace gpubench
{

// Timing.

inline double millisecondsSince(const std::chrono::steady_clock::time_point& start)
{
  return std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start)
    .count();
}

struct GpuTimes
{
  bool ok = false;
  std::string message;
  double kernelMs = 0.0;                     // best of the timed runs
  double totalMs = 0.0;                      // best of the timed runs
  std::vector<vao::cuda::PassTiming> passes; // of the run with the best kernel time
  double uploadGBs = 0.0;   // host-to-device copies (pinned staging), best run; 0: none
  double downloadGBs = 0.0; // device-to-host
};

/// One warm-up call, then the best kernel and the best end-to-end time of `repeat` calls.
template <class Call>
GpuTimes timeGpu(const Call& call, int repeat)
{
  GpuTimes times;
  vao::cuda::Timing timing;
  vao::Status status = call(&timing);
  if (!status.ok)
  {
    times.message = status.message;
    return times;
  }
  times.kernelMs = times.totalMs = 1e300;
  for (int r = 0; r < repeat; ++r)
  {
    timing = vao::cuda::Timing();
    status = call(&timing);
    if (!status.ok)
    {
      times.message = status.message;
      return times;
    }
    if (timing.kernelMilliseconds < times.kernelMs)
    {
      times.kernelMs = timing.kernelMilliseconds;
      times.passes = timing.passes;
    }
    times.totalMs = std::min(times.totalMs, timing.totalMilliseconds);
    if (timing.uploadMilliseconds > 0)
      times.uploadGBs =
        std::max(times.uploadGBs, timing.uploadBytes / (timing.uploadMilliseconds * 1e6));
    if (timing.downloadMilliseconds > 0)
      times.downloadGBs =
        std::max(times.downloadGBs, timing.downloadBytes / (timing.downloadMilliseconds * 1e6));
  }
  times.ok = true;
  return times;
}

/// Best wall-clock time of `repeat` CPU calls (the first one warms the caches).
template <class Call>
double timeCpu(const Call& call, int repeat)
{
  double best = 1e300;
  for (int r = 0; r < repeat; ++r)
  {
    const auto start = std::chrono::steady_clock::now();
    if (!call().ok)
    {
      return -1.0;
    }
    best = std::min(best, millisecondsSince(start));
  }
  return best;
}

// ---------------------------------------------------------------------------------------
// The bars of the issue.

struct Bar
{
  std::string verdict; // PASS, FAIL or SKIP
  std::string text;
};

inline std::vector<Bar> bars;
inline bool callFailed = false;

inline void bar(const std::string& verdict, const std::string& text)
{
  bars.push_back({ verdict, text });
  std::printf("%s %s\n", verdict.c_str(), text.c_str());
}

inline std::string format(const char* pattern, ...) __attribute__((format(printf, 1, 2)));
inline std::string format(const char* pattern, ...)
{
  char buffer[1024];
  va_list args;
  va_start(args, pattern);
  std::vsnprintf(buffer, sizeof(buffer), pattern, args);
  va_end(args);
  return buffer;
}

} // namespace gpubench
