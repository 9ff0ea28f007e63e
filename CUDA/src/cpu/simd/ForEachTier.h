// Compiles the lane code of the file named by VAO_TIER_FILE once per vector tier: in
// namespace avx2 with VAO_LANES / VAO_LANES_ENTRY the AVX2 attributes, and in namespace
// avx512 with the AVX-512 ones (CpuDispatch.h), so that a -inl.h file is written once over
// the names of DoubleLanes.h. Include it where the tiers' namespaces belong, right after
// defining VAO_TIER_FILE (a quoted path); no include guard: once per -inl.h file.
#if VAO_HAVE_AVX2_TARGET
namespace avx2
{
#define VAO_LANES VAO_AVX2_HELPER
#define VAO_LANES_ENTRY VAO_AVX2_INLINE
#include VAO_TIER_FILE
#undef VAO_LANES
#undef VAO_LANES_ENTRY
} // namespace avx2

namespace avx512
{
#define VAO_LANES VAO_AVX512_HELPER
#define VAO_LANES_ENTRY VAO_AVX512_INLINE
#include VAO_TIER_FILE
#undef VAO_LANES
#undef VAO_LANES_ENTRY
} // namespace avx512
#endif
#undef VAO_TIER_FILE
