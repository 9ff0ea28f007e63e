// Storage of the large arrays: blocks aligned to 2 MiB and advised to use transparent huge
// pages (see vao/Storage.h).
#include "vao/Storage.h"

#include <cstdlib>
#include <limits>

#if defined(__linux__)
#include <sys/mman.h>
#endif
#if defined(_WIN32)
#include <malloc.h>
#endif

namespace vao
{
namespace detail
{

void* allocateStorage(std::size_t bytes)
{
  constexpr std::size_t kHugePage = std::size_t(2) << 20;
  if (bytes > std::numeric_limits<std::size_t>::max() - kHugePage)
  {
    return nullptr; // no such block; rounding it up to whole huge pages would wrap
  }
#if defined(_WIN32)
  return _aligned_malloc(bytes > 0 ? bytes : 1, bytes < kHugePage ? 64 : kHugePage);
#else
  if (bytes < kHugePage)
  {
    return std::malloc(bytes > 0 ? bytes : 1);
  }
  const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  void* block = std::aligned_alloc(kHugePage, rounded);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (block)
  {
    madvise(block, rounded, MADV_HUGEPAGE); // advisory: ignored where THP is off
  }
#endif
  return block;
#endif
}

void freeStorage(void* block) noexcept
{
#if defined(_WIN32)
  _aligned_free(block);
#else
  std::free(block);
#endif
}

} // namespace detail
} // namespace vao
