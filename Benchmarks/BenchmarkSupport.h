// What the benchmark's tables share: the options, the clock, the thread count, and the
// peers' scripts (Python, run in the same session as our code).
#pragma once

#include "ScanPath.h"

#include <algorithm>
#include <chrono>
#include <string>
#include <thread>

#ifndef VAO_DATA_DIR
#define VAO_DATA_DIR "Data"
#endif
#ifndef VAO_EXTRA_DATA_DIR
#define VAO_EXTRA_DATA_DIR ""
#endif
#ifndef VAO_DEFAULT_SCIPY_PEER
#define VAO_DEFAULT_SCIPY_PEER "scipy_peer.py"
#endif
#ifndef VAO_DEFAULT_SCIPY_EDT_PEER
#define VAO_DEFAULT_SCIPY_EDT_PEER "scipy_edt_peer.py"
#endif
#ifndef VAO_DEFAULT_SCIPY_BLUR_PEER
#define VAO_DEFAULT_SCIPY_BLUR_PEER "scipy_blur_peer.py"
#endif

namespace vaobench
{

struct Options
{
  std::string data = VAO_EXTRA_DATA_DIR; // --data: scans the repository does not ship
  std::string scipy = VAO_DEFAULT_SCIPY_PEER;
  std::string scipyEdt = VAO_DEFAULT_SCIPY_EDT_PEER;
  std::string scipyBlur = VAO_DEFAULT_SCIPY_BLUR_PEER;
  bool sweepingOnly = false;
  bool pennerOnly = false;
  bool relightOnly = false; // --relight: the surface query rates of --penner alone
  bool volumetricOnly = false;
  int repeat = 3;
  bool exact = false;
  int threads = 0;
};

/// Where a scan is: under Data/, else under `extra` (--data); see ScanPath.h.
inline std::string ScanPath(const std::string& extra, const std::string& relative)
{
  return vaodata::ScanPath(VAO_DATA_DIR, extra, relative);
}

inline int ResolvedThreads(int requested)
{
  return requested > 0 ? requested
                       : static_cast<int>(std::max(1u, std::thread::hardware_concurrency()));
}

inline double Seconds(const std::chrono::steady_clock::time_point& start)
{
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

} // namespace vaobench
