// Storage of the large arrays: blocks aligned to 2 MiB and advised to use transparent huge
// pages, the outputs' blocks kept for the next output of their size, and sparse
// reservations backed page by page (see vao/Storage.h).
#include "cpu/common/SparseStorage.h"

#include <cerrno>
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <mutex>
#include <new>
#include <unordered_map>
#include <utility>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif
#if defined(__unix__)
#include <unistd.h>
#endif
#if defined(_WIN32)
#include <malloc.h>
#endif

namespace vao
{

namespace
{
constexpr std::size_t kHugePage = std::size_t(2) << 20;

void* allocateBlock(std::size_t bytes)
{
#if defined(_WIN32)
  return _aligned_malloc(bytes > 0 ? bytes : 1, bytes < kHugePage ? 64 : kHugePage);
#else
  if (bytes < kHugePage)
  {
    return std::malloc(bytes > 0 ? bytes : 1);
  }
  void* block = std::aligned_alloc(kHugePage, bytes);
#if defined(__linux__) && defined(MADV_HUGEPAGE)
  if (block)
  {
    madvise(block, bytes, MADV_HUGEPAGE); // advisory: ignored where THP is off
  }
#endif
  return block;
#endif
}

void freeBlock(void* block) noexcept
{
#if defined(_WIN32)
  _aligned_free(block);
#else
  std::free(block);
#endif
}

std::size_t physicalMemory()
{
#if defined(__unix__)
  const long pages = sysconf(_SC_PHYS_PAGES), pageSize = sysconf(_SC_PAGE_SIZE);
  if (pages > 0 && pageSize > 0)
  {
    return static_cast<std::size_t>(pages) * static_cast<std::size_t>(pageSize);
  }
#endif
  return std::size_t(8) << 30;
}

/// The large blocks' sizes (freeing one by pointer must know it), and the blocks
/// recycleStorage keeps, oldest first.
struct LargeBlocks
{
  std::mutex lock;
  std::unordered_map<void*, std::size_t> live;
  std::vector<std::pair<void*, std::size_t>> kept;
  std::size_t keptBytes = 0;
  std::size_t keptAtMost = physicalMemory() / 8;

  /// Frees the oldest kept blocks until at most `bytes` are kept (under the lock: nothing
  /// here can throw).
  void keepAtMost(std::size_t bytes) noexcept
  {
    std::size_t count = 0;
    for (; this->keptBytes > bytes; ++count)
    {
      freeBlock(this->kept[count].first);
      this->keptBytes -= this->kept[count].second;
    }
    this->kept.erase(this->kept.begin(), this->kept.begin() + static_cast<std::ptrdiff_t>(count));
  }
};

/// Made in static storage on first use (no allocation that could throw) and never
/// destroyed: VTK arrays may free their blocks during the static destruction at exit.
LargeBlocks& largeBlocks()
{
  alignas(LargeBlocks) static unsigned char storage[sizeof(LargeBlocks)];
  static LargeBlocks* blocks = new (storage) LargeBlocks;
  return *blocks;
}

/// Large blocks start on a huge page; malloc's small ones practically never do, and those
/// that do are looked up and not found.
bool mayBeLarge(const void* block)
{
  return reinterpret_cast<std::uintptr_t>(block) % kHugePage == 0;
}

} // namespace

void* allocateStorage(std::size_t bytes)
{
  if (bytes > std::numeric_limits<std::size_t>::max() - kHugePage)
  {
    return nullptr; // no such block; rounding it up to whole huge pages would wrap
  }
  if (bytes < kHugePage)
  {
    return allocateBlock(bytes);
  }
  const std::size_t rounded = (bytes + kHugePage - 1) / kHugePage * kHugePage;
  LargeBlocks& blocks = largeBlocks();
  std::lock_guard<std::mutex> hold(blocks.lock);
  for (std::size_t i = blocks.kept.size(); i-- > 0;) // the most recently kept first
  {
    if (blocks.kept[i].second == rounded)
    {
      void* block = blocks.kept[i].first;
      try
      {
        blocks.live.emplace(block, rounded);
      }
      catch (...)
      {
        return nullptr; // the block stays kept
      }
      blocks.keptBytes -= rounded;
      blocks.kept.erase(blocks.kept.begin() + static_cast<std::ptrdiff_t>(i));
      return block;
    }
  }
  blocks.keepAtMost(0); // none fits: they must not add to the peak
  void* block = allocateBlock(rounded);
  try
  {
    if (block)
    {
      blocks.live.emplace(block, rounded);
    }
  }
  catch (...)
  {
    freeBlock(block);
    return nullptr;
  }
  return block;
}

void freeStorage(void* block) noexcept
{
  if (mayBeLarge(block) && block)
  {
    LargeBlocks& blocks = largeBlocks();
    std::lock_guard<std::mutex> hold(blocks.lock);
    blocks.live.erase(block);
  }
  freeBlock(block);
}

void recycleStorage(void* block) noexcept
{
  if (!mayBeLarge(block) || !block)
  {
    freeBlock(block);
    return;
  }
  LargeBlocks& blocks = largeBlocks();
  std::lock_guard<std::mutex> hold(blocks.lock);
  const auto found = blocks.live.find(block);
  const std::size_t bytes = found == blocks.live.end() ? 0 : found->second;
  if (bytes > 0)
  {
    blocks.live.erase(found);
  }
  if (bytes == 0 || bytes > blocks.keptAtMost)
  {
    freeBlock(block); // a small block, or one too large to keep
    return;
  }
  blocks.keepAtMost(blocks.keptAtMost - bytes); // room for this one
  try
  {
    blocks.kept.emplace_back(block, bytes);
  }
  catch (...)
  {
    freeBlock(block);
    return;
  }
  blocks.keptBytes += bytes;
#if defined(__linux__) && defined(MADV_FREE)
  madvise(block, bytes, MADV_FREE); // reclaimable; zero pages where the system takes them
#endif
}

std::size_t keptStorageBytes() noexcept
{
  LargeBlocks& blocks = largeBlocks();
  std::lock_guard<std::mutex> hold(blocks.lock);
  return blocks.keptBytes;
}

void releaseKeptStorage() noexcept
{
  LargeBlocks& blocks = largeBlocks();
  std::lock_guard<std::mutex> hold(blocks.lock);
  blocks.keepAtMost(0);
}

namespace detail
{

std::size_t setKeptStorageLimit(std::size_t bytes) noexcept
{
  LargeBlocks& blocks = largeBlocks();
  std::lock_guard<std::mutex> hold(blocks.lock);
  const std::size_t before = blocks.keptAtMost;
  blocks.keptAtMost = bytes;
  blocks.keepAtMost(bytes);
  return before;
}

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
