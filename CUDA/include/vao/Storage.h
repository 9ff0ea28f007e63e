// Storage of the large arrays (pyramid levels, sweep fields, box extrema, the filters'
// outputs): blocks of 2 MiB and more are aligned to 2 MiB and, on Linux, advised to use
// transparent huge pages, as NumPy does for its large arrays. The first touch of 4 KiB
// pages costs a page fault each, which on some virtual machines costs more than the
// filter's own work; a huge page takes one fault for 2 MiB instead of 512.
#pragma once

#include <cstddef>
#include <new>
#include <type_traits>
#include <utility>

namespace vao
{
/// A block of at least `bytes` bytes for a large array, uninitialised (first touched by
/// whoever writes it first: the workers, in parallel), or nullptr when it cannot be had;
/// it never throws. Below 2 MiB the block comes from std::malloc (aligned for any scalar
/// type; 64 bytes on Windows). From 2 MiB it is aligned to 2 MiB and, on Linux, rounded up
/// to whole 2 MiB pages and advised to use transparent huge pages (advice the kernel may
/// ignore, e.g. where THP is off). 0 bytes give a block of 1. Sizes within 2 MiB of
/// SIZE_MAX, which the rounding would wrap, give nullptr. Free it with freeStorage, or
/// recycleStorage.
void* allocateStorage(std::size_t bytes);
/// Frees a block of allocateStorage (nullptr: nothing). Its signature is that of a VTK
/// array's free function (vtkAbstractArray::SetArrayFreeFunction), so a VTK array can own
/// such a block without a copy.
void freeStorage(void* block) noexcept;
/// Frees a block of allocateStorage that held a filter's output (the free function of the
/// VTK arrays the filters hand over), keeping a block of 2 MiB or more for the next
/// allocateStorage of the same rounded size: a filter run again, or a new one on data of
/// the same size, writes into pages the system has already backed, instead of pages it
/// must first zero and map (docs/performance.md, Storage). Kept blocks are freed
/// lazily on Linux (MADV_FREE: the system takes them back when it runs short, without
/// swapping), at most an eighth of the physical memory is kept, and an allocateStorage of
/// a size none of them has gives them all back first, so they never sit beside a new block.
void recycleStorage(void* block) noexcept;
/// The bytes recycleStorage keeps, and a way to give them all back now.
std::size_t keptStorageBytes() noexcept;
void releaseKeptStorage() noexcept;

/// An array of T in storage. resize leaves the elements uninitialised: the kernels write
/// every one, in parallel, so a fresh array is first touched by the threads that fill it
/// instead of by one serial zero-fill. release() hands the block to a new owner (a VTK
/// array, without a copy), who frees it with freeStorage or recycleStorage.
template <class T>
class StorageArray
{
  static_assert(std::is_trivially_copyable<T>::value, "StorageArray holds plain values");

public:
  StorageArray() = default;
  StorageArray(const StorageArray& other) { *this = other; }
  StorageArray(StorageArray&& other) noexcept { this->swap(other); }
  ~StorageArray() { freeStorage(this->Data); }
  StorageArray& operator=(const StorageArray& other)
  {
    if (this != &other)
    {
      this->resize(other.Size);
      for (std::size_t i = 0; i < other.Size; ++i)
        this->Data[i] = other.Data[i];
    }
    return *this;
  }
  StorageArray& operator=(StorageArray&& other) noexcept
  {
    StorageArray moved(std::move(other));
    this->swap(moved);
    return *this;
  }
  void swap(StorageArray& other) noexcept
  {
    std::swap(this->Data, other.Data);
    std::swap(this->Size, other.Size);
  }
  /// Keeps the block when the size is unchanged (a rebuild of the same size); throws
  /// std::bad_alloc when the block cannot be had, leaving the array as it was.
  void resize(std::size_t n)
  {
    if (n == this->Size)
      return;
    T* block = nullptr;
    if (n > 0)
    {
      block = n <= static_cast<std::size_t>(-1) / sizeof(T)
        ? static_cast<T*>(allocateStorage(n * sizeof(T)))
        : nullptr;
      if (!block)
        throw std::bad_alloc();
    }
    freeStorage(this->Data);
    this->Data = block;
    this->Size = n;
  }
  void assign(std::size_t n, T value)
  {
    this->resize(n);
    for (std::size_t i = 0; i < n; ++i)
      this->Data[i] = value;
  }
  T* release() noexcept
  {
    T* block = this->Data;
    this->Data = nullptr;
    this->Size = 0;
    return block;
  }
  std::size_t size() const noexcept { return this->Size; }
  bool empty() const noexcept { return this->Size == 0; }
  T* data() noexcept { return this->Data; }
  const T* data() const noexcept { return this->Data; }
  T& operator[](std::size_t i) noexcept { return this->Data[i]; }
  const T& operator[](std::size_t i) const noexcept { return this->Data[i]; }
  T* begin() noexcept { return this->Data; }
  T* end() noexcept { return this->Data + this->Size; }
  const T* begin() const noexcept { return this->Data; }
  const T* end() const noexcept { return this->Data + this->Size; }

private:
  T* Data = nullptr;
  std::size_t Size = 0;
};

} // namespace vao
