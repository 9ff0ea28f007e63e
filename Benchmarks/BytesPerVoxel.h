// The bytes per voxel each kernel moves, measured under valgrind (BytesPerVoxel.cxx).
#pragma once

#include <string>

namespace vaobench
{

/// The table: this program run again under valgrind's cache simulation, once per workload.
void BenchmarkBytes();

/// One workload, its kernel call alone instrumented (what the table runs), or "all" of
/// them one after another; 0 on success.
int RunBytesWorkload(const std::string& name);

} // namespace vaobench
