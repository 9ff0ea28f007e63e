// Resident memory of this process (Linux): the current size, the peak (VmHWM) and a reset
// of the peak, for the memory table (vao_memory) and the streaming tool (vao_stream).
#pragma once

#include <cstdlib>
#include <cstring>
#include <fstream>
#include <string>

namespace vao_bench
{

/// A field of /proc/self/status in bytes ("VmRSS:", "VmHWM:"); -1 when unreadable.
inline long long StatusBytes(const char* field)
{
  std::ifstream status("/proc/self/status");
  std::string line;
  while (std::getline(status, line))
  {
    if (line.rfind(field, 0) == 0)
    {
      return std::atoll(line.c_str() + std::strlen(field)) * 1024LL;
    }
  }
  return -1;
}

/// Resets VmHWM to the current RSS (Linux >= 4.0). False when the kernel refuses.
inline bool ResetPeak()
{
  std::ofstream clear("/proc/self/clear_refs");
  clear << "5";
  clear.close();
  return !clear.fail();
}

} // namespace vao_bench
