// libFuzzer target: every entry point of the kernel library on one fuzz input
// (FuzzEntryPoints.h says what is checked). Built by `bash .ci/setup.sh fuzz`.
#include "FuzzEntryPoints.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size)
{
  vaofuzz::fuzzOnce(data, size);
  return 0;
}
