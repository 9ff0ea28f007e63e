// Where a real scan is, for the tests and the benchmarks alike: under Data/ (the scans the
// repository ships), else under a folder of further scans laid out the same way
// (VAO_EXTRA_DATA_DIR, or a benchmark's --data), else the Data/ path, so that a reader's
// message names the file that is missing.
#pragma once

#include <fstream>
#include <string>

namespace vaodata
{

inline std::string ScanPath(
  const std::string& shipped, const std::string& extra, const std::string& relative)
{
  const std::string inShipped = shipped + "/" + relative;
  if (std::ifstream(inShipped).good() || extra.empty())
    return inShipped;
  const std::string inExtra = extra + "/" + relative;
  return std::ifstream(inExtra).good() ? inExtra : inShipped;
}

} // namespace vaodata
