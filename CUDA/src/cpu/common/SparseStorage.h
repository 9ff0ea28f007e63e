// The kernel's own ways into the storage of vao/Storage.h: sparse reservations (the tiles
// of a SurfacePyramid) and the limit of the kept blocks (the tests shrink it).
#pragma once

#include "vao/Storage.h"

#include <cstddef>

namespace vao
{
namespace detail
{
/// Sets the most bytes recycleStorage keeps (by default an eighth of the physical memory),
/// giving back the oldest kept blocks beyond it, and returns the limit it replaces.
std::size_t setKeptStorageLimit(std::size_t bytes) noexcept;

/// A zero-filled reservation of `bytes` whose 4 KiB pages take memory only once written
/// (nullptr when it cannot be had): for data kept sparsely at fixed places, such as the
/// tiles of a level built on demand. Never backed by huge pages, which would fill in 2 MiB
/// around each page written. Freed with freeSparseStorage(block, bytes).
void* allocateSparseStorage(std::size_t bytes);
void freeSparseStorage(void* block, std::size_t bytes) noexcept;
/// Backs [at, at + bytes) of a sparse reservation (page aligned) before it is written, in
/// one call instead of a fault per page where the system can (Linux 5.14 and later).
/// False when the system has no memory left for them (writing them would bring the
/// out-of-memory killer): the caller fails cleanly instead.
bool prepareSparseStorage(void* at, std::size_t bytes) noexcept;
} // namespace detail
} // namespace vao
