// Storage of the large arrays: blocks aligned to 2 MiB and advised to use transparent huge
// pages, and sparse reservations backed page by page (see vao/Storage.h).
#include "vao/Storage.h"

#include <cerrno>
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

namespace detail
{

void* allocateSparseStorage(std::size_t bytes)
{
  if (bytes == 0)
  {
    bytes = 1;
  }
#if defined(__linux__)
  void* block = mmap(
    nullptr, bytes, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS | MAP_NORESERVE, -1, 0);
  if (block == MAP_FAILED)
  {
    return nullptr;
  }
#if defined(MADV_NOHUGEPAGE)
  madvise(block, bytes, MADV_NOHUGEPAGE);
#endif
  return block;
#else
  return std::calloc(bytes, 1); // large blocks come zeroed from the system, untouched
#endif
}

void freeSparseStorage(void* block, std::size_t bytes) noexcept
{
  if (!block)
  {
    return;
  }
#if defined(__linux__)
  munmap(block, bytes > 0 ? bytes : 1);
#else
  (void)bytes;
  std::free(block);
#endif
}

bool prepareSparseStorage(void* at, std::size_t bytes) noexcept
{
#if defined(__linux__)
#if !defined(MADV_POPULATE_WRITE)
  constexpr int MADV_POPULATE_WRITE =
    23; // Linux 5.14; older kernels refuse it (EINVAL), harmlessly
#endif
  return madvise(at, bytes, MADV_POPULATE_WRITE) == 0 || errno != ENOMEM;
#else
  (void)at;
  (void)bytes;
  return true;
#endif
}

} // namespace detail
} // namespace vao
