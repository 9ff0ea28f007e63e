#!/usr/bin/env bash
# The kernel library's tests under the sanitizers:
#  1. AddressSanitizer + UndefinedBehaviorSanitizer (float-cast-overflow included), every
#     finding fatal: build-asan/;
#  2. ThreadSanitizer: build-tsan/.
# With --filters, also the VTK filters' C++ tests under ASan + UBSan (the whole project
# built instrumented in build-asan-filters/: about 22 minutes more on two cores). With
# --ci (what .ci/run does), ThreadSanitizer runs only the tests that exercise the threads
# (the pool, the sweeps' wavefront, the streamed statistics), to keep CI short.
# GCC's sanitizers come with g++ (libasan8, libubsan1, libtsan2). CI runs the kernel part.
set -euo pipefail
cd "$(dirname "$0")/.."
# UBSan's object-size, null and alignment checks are left out (a quarter of the instrumented
# build): ASan reports the accesses out of bounds and through null itself, and the
# misaligned access that matters on x86, an aligned vector load, faults in the tests anyway.
asan="-fsanitize=address,undefined,float-cast-overflow -fno-sanitize=object-size,null,alignment -fno-sanitize-recover=all -fno-omit-frame-pointer -g"
export ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1
export TSAN_OPTIONS=halt_on_error=1:second_deadlock_stack=1
# -O1, as the sanitizers' authors advise, with assertions on: the instrumented kernel library
# and its tests build much faster than at -O3, and the tests run no slower under ASan.
sanitizerBuild=(-DCMAKE_BUILD_TYPE=Debug "-DCMAKE_CXX_FLAGS_DEBUG=-O1 -g")

echo "== kernel tests under AddressSanitizer + UndefinedBehaviorSanitizer"
cmake -S CUDA -B build-asan -G Ninja "${sanitizerBuild[@]}" -DVAO_ENABLE_CUDA=OFF \
  -DCMAKE_CXX_FLAGS="$asan" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined"
cmake --build build-asan -j "$(nproc)"
ctest --test-dir build-asan -j "$(nproc)" --output-on-failure

echo "== kernel tests under ThreadSanitizer"
cmake -S CUDA -B build-tsan -G Ninja "${sanitizerBuild[@]}" -DVAO_ENABLE_CUDA=OFF \
  -DCMAKE_CXX_FLAGS="-fsanitize=thread -g" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=thread"
cmake --build build-tsan -j "$(nproc)"
# Death tests fork, which ThreadSanitizer does not follow: they run in the ASan build.
# With --ci, the box statistics' typed and precision suites and the flat backgrounds stay
# in the ASan build: they repeat the threads' pattern of BoxStatistics.* and Openness.*
# for each type and magnitude. So do the surface pyramid's queries on every SIMD tier (the
# aborted queries' test runs the same threads) and block sweeping's every split (its rounds'
# test runs the same exchange): they were the longest part of the ThreadSanitizer run.
tsanSkipped="ABrokenPropertyIsReported"
tsanTests=()
if [[ "${1:-}" == "--ci" ]]; then
  tsanTests=(-R "WorkerPool|Sweep|BlockSweeping|Openness|^BoxStatistics\\.|Pyramid")
  tsanSkipped+="|QueriesEqualTheWholePyramidBitForBitOnEveryTier|BlockSweeping\\.EverySplit"
fi
ctest --test-dir build-tsan -j "$(nproc)" --output-on-failure -E "$tsanSkipped" "${tsanTests[@]}"

if [[ "${1:-}" == "--filters" ]]; then
  echo "== VTK filter tests under AddressSanitizer + UndefinedBehaviorSanitizer"
  # VTK's own libraries are not instrumented; leaks inside them are not ours.
  export ASAN_OPTIONS=detect_leaks=0:abort_on_error=1
  cmake -S . -B build-asan-filters -G Ninja "${sanitizerBuild[@]}" -DVAO_ENABLE_CUDA=OFF \
    -DCMAKE_CXX_FLAGS="$asan" -DCMAKE_EXE_LINKER_FLAGS="-fsanitize=address,undefined" \
    -DCMAKE_SHARED_LINKER_FLAGS="-fsanitize=address,undefined"
  cmake --build build-asan-filters -j "$(nproc)"
  # The out-of-memory tests make allocations fail on purpose, which ASan's allocator
  # reports as its own error: they run in the plain build.
  ctest --test-dir build-asan-filters -j "$(nproc)" --output-on-failure -L "kernels|filters" -LE rendering \
    -E "OutOfMemory"
fi
