// The storage of the large arrays (vao/Storage.h): uninitialised arrays that keep their
// block, hand it over, refuse sizes they cannot hold, and ask Linux for huge pages; and
// the outputs' blocks, kept for the next block of their size.
#include "cpu/common/SparseStorage.h"
#include "vao/Storage.h"

#include <gtest/gtest.h>

#include <cstdint>
#include <fstream>
#include <limits>
#include <new>
#include <sstream>
#include <string>

namespace
{

constexpr std::size_t kHugePage = std::size_t(2) << 20;

TEST(Storage, LargeBlocksAreAlignedToAHugePage)
{
  vao::StorageArray<float> a;
  a.resize(3 * kHugePage / sizeof(float) + 5);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(a.data()) % kHugePage, 0u);
  vao::StorageArray<double> small;
  small.resize(3);
  EXPECT_EQ(reinterpret_cast<std::uintptr_t>(small.data()) % alignof(double), 0u);
}

TEST(Storage, ResizeKeepsTheBlockOfTheSameSizeAndCopiesAreDeep)
{
  vao::StorageArray<int> a;
  a.assign(1000, 7);
  const int* block = a.data();
  a.resize(1000);
  EXPECT_EQ(a.data(), block);
  vao::StorageArray<int> b(a);
  ASSERT_EQ(b.size(), 1000u);
  EXPECT_NE(b.data(), a.data());
  b[999] = 8;
  EXPECT_EQ(a[999], 7);
  vao::StorageArray<int> c(std::move(b));
  EXPECT_TRUE(b.empty());
  EXPECT_EQ(c[999], 8);
  EXPECT_EQ(c[0], 7);
  int* owned = c.release();
  EXPECT_TRUE(c.empty());
  EXPECT_EQ(owned[1], 7);
  vao::freeStorage(owned);
  c.resize(0);
  EXPECT_EQ(c.data(), nullptr);
}

TEST(Storage, SizesBeyondMemoryThrowAndLeaveTheArray)
{
  vao::StorageArray<double> a;
  a.assign(4, 1.5);
  // n * sizeof(double) overflows size_t, and the block rounded up to whole huge pages
  // would: neither may wrap to a small block. (Both are refused before the allocator,
  // which AddressSanitizer would stop on a request this large.)
  EXPECT_THROW(a.resize(std::numeric_limits<std::size_t>::max() / 4), std::bad_alloc);
  ASSERT_EQ(a.size(), 4u);
  EXPECT_EQ(a[3], 1.5);
  EXPECT_EQ(vao::allocateStorage(std::numeric_limits<std::size_t>::max() - 4096), nullptr);
}

TEST(Storage, RecycledBlocksServeTheNextBlockOfTheirSizeOnly)
{
  vao::releaseKeptStorage();
  ASSERT_EQ(vao::keptStorageBytes(), 0u);
  // 3 huge pages and 5 bytes round up to 4 huge pages: a block of 4 is the same size.
  auto* first = static_cast<unsigned char*>(vao::allocateStorage(3 * kHugePage + 5));
  ASSERT_NE(first, nullptr);
  for (std::size_t i = 0; i < 3 * kHugePage + 5; ++i)
    first[i] = static_cast<unsigned char>(i);
  vao::recycleStorage(first);
  EXPECT_EQ(vao::keptStorageBytes(), 4 * kHugePage);
  auto* again = static_cast<unsigned char*>(vao::allocateStorage(4 * kHugePage));
  EXPECT_EQ(again, first);
  EXPECT_EQ(vao::keptStorageBytes(), 0u);
  for (std::size_t i = 0; i < 4 * kHugePage; ++i) // lazily freed pages are writable again
    again[i] = 7;
  EXPECT_EQ(again[4 * kHugePage - 1], 7);
  // A block of another size finds none to take, and every kept block is given back first.
  vao::recycleStorage(again);
  EXPECT_EQ(vao::keptStorageBytes(), 4 * kHugePage);
  void* other = vao::allocateStorage(2 * kHugePage);
  ASSERT_NE(other, nullptr);
  EXPECT_EQ(vao::keptStorageBytes(), 0u);
  // Small blocks, blocks freed with freeStorage, and nullptr are not kept.
  vao::recycleStorage(vao::allocateStorage(100));
  vao::freeStorage(other);
  vao::recycleStorage(nullptr);
  EXPECT_EQ(vao::keptStorageBytes(), 0u);
  // Kept blocks are given back on demand.
  vao::recycleStorage(vao::allocateStorage(kHugePage));
  EXPECT_EQ(vao::keptStorageBytes(), kHugePage);
  vao::releaseKeptStorage();
  EXPECT_EQ(vao::keptStorageBytes(), 0u);
}

TEST(Storage, RecycledBlocksBeyondTheLimitGoBackOldestFirst)
{
  vao::releaseKeptStorage();
  const std::size_t limit = vao::detail::setKeptStorageLimit(3 * kHugePage);
  void* blocks[4];
  for (void*& block : blocks)
  {
    block = vao::allocateStorage(kHugePage);
    ASSERT_NE(block, nullptr);
  }
  for (void* block : blocks)
    vao::recycleStorage(block);
  // The fourth pushed the first out; the newest comes back first.
  EXPECT_EQ(vao::keptStorageBytes(), 3 * kHugePage);
  void* taken[3];
  for (void*& block : taken)
    block = vao::allocateStorage(kHugePage);
  EXPECT_EQ(taken[0], blocks[3]);
  EXPECT_EQ(taken[1], blocks[2]);
  EXPECT_EQ(taken[2], blocks[1]);
  EXPECT_EQ(vao::keptStorageBytes(), 0u);
  for (void* block : taken)
    vao::freeStorage(block);
  // A block larger than the limit is freed, and the kept one stays.
  void* large = vao::allocateStorage(4 * kHugePage);
  ASSERT_NE(large, nullptr);
  vao::recycleStorage(vao::allocateStorage(kHugePage));
  vao::recycleStorage(large);
  EXPECT_EQ(vao::keptStorageBytes(), kHugePage);
  // Lowering the limit gives back the oldest blocks beyond it.
  vao::detail::setKeptStorageLimit(0);
  EXPECT_EQ(vao::keptStorageBytes(), 0u);
  vao::detail::setKeptStorageLimit(limit);
}

#if defined(__linux__)
/// The "THPeligible" line of the mapping that holds `address` in /proc/self/smaps
/// (-1 when the kernel does not report it).
int hugePageEligible(const void* address)
{
  std::ifstream smaps("/proc/self/smaps");
  const auto at = reinterpret_cast<std::uintptr_t>(address);
  std::string line;
  bool inside = false;
  while (std::getline(smaps, line))
  {
    std::uintptr_t lo = 0, hi = 0;
    char dash = 0;
    std::istringstream head(line);
    if (head >> std::hex >> lo >> dash >> hi && dash == '-')
    {
      inside = at >= lo && at < hi;
      continue;
    }
    if (inside && line.rfind("THPeligible:", 0) == 0)
      return std::stoi(line.substr(12));
  }
  return -1;
}

TEST(Storage, LargeBlocksAskForTransparentHugePages)
{
  std::ifstream mode("/sys/kernel/mm/transparent_hugepage/enabled");
  std::string modes;
  std::getline(mode, modes);
  if (modes.empty() || modes.find("[never]") != std::string::npos)
    GTEST_SKIP() << "transparent huge pages are off on this kernel ('" << modes << "')";
  vao::StorageArray<float> a;
  a.resize(8 * kHugePage / sizeof(float));
  const int eligible = hugePageEligible(a.data() + a.size() / 2);
  if (eligible < 0)
    GTEST_SKIP() << "this kernel's smaps does not report THPeligible";
  EXPECT_EQ(eligible, 1) << "THP mode " << modes << ": the block was not advised";
}
#endif

} // namespace
