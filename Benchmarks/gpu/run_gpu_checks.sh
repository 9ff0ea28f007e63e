#!/usr/bin/env bash
# The GPU checks in one go, from the repository root of a machine with an NVIDIA GPU:
#   Benchmarks/gpu/run_gpu_checks.sh [benchmark options, e.g. --quick]
# Prints the device and nvcc, configures Benchmarks/gpu as a standalone project into
# build-gpu (Release; CUDA architectures native when CMake and the GPU allow, else 90),
# builds it, runs the GPU tests (vao_cuda_tests) and the CPU kernel tests, then the GPU
# benchmark with its cupy peer. Everything goes to stdout and, when $OUT is set, to
# $OUT/gpu_checks.txt as well.
#
# Exit status: 0 everything ran and the tests passed; 1 configure/build failed or a test
# failed (or the benchmark reported a failed GPU call, or was cut by the budget); 3 the
# tests could not be built (GoogleTest missing) although the rest passed; 4 no usable CUDA
# device (the GPU tests skipped, the benchmark printed "no CUDA device: ..."). The benchmark's PASS/FAIL bars are
# reported, not part of the status (pass --strict to the benchmark to change that).
# Budget: about 1-3 min to build, < 1 min of tests, ~1-2 min of benchmark on an H100; each
# step is also cut at the remainder of VAO_GPU_CHECKS_BUDGET seconds (default 450), so the
# whole script ends within about 8 minutes whatever happens.
set -u

ROOT="$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)"
BUILD="${VAO_GPU_BUILD_DIR:-$ROOT/build-gpu}"

BUDGET="${VAO_GPU_CHECKS_BUDGET:-450}"

section() { printf '\n===== %s =====\n' "$*"; }

# Seconds left of the budget (at least 10), for `timeout`.
left() { local s=$((BUDGET - SECONDS)); echo $((s > 10 ? s : 10)); }

version_at_least() { # version_at_least 3.25.1 3.24
  [ "$(printf '%s\n%s\n' "$2" "$1" | sort -V | head -n1)" = "$2" ]
}

run_checks() {
  local status=0 tests_built=1 skipped=0
  section "device"
  date -u '+%Y-%m-%dT%H:%M:%SZ'
  if command -v nvidia-smi >/dev/null 2>&1; then
    nvidia-smi -L || echo "nvidia-smi -L failed"
    nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm,clocks.max.mem --format=csv || true
  else
    echo "nvidia-smi not found"
  fi
  section "toolchain"
  local nvcc_path="" arch=90 cmake_version
  nvcc_path="$(command -v nvcc || true)"
  if [ -z "$nvcc_path" ] && [ -x /usr/local/cuda/bin/nvcc ]; then
    nvcc_path=/usr/local/cuda/bin/nvcc
  fi
  if [ -n "$nvcc_path" ]; then
    "$nvcc_path" --version
  else
    echo "nvcc not found: the kernel library will be CPU-only"
  fi
  cmake --version | head -n1
  cmake_version="$(cmake --version | head -n1 | awk '{print $3}')"
  if version_at_least "$cmake_version" 3.24 && nvidia-smi -L >/dev/null 2>&1; then
    arch=native
  fi
  echo "CMAKE_CUDA_ARCHITECTURES=$arch; $(nproc) cores"
  python3 --version 2>&1 || echo "python3 not found (no cupy peer)"

  section "configure ($BUILD)"
  local generator=()
  if command -v ninja >/dev/null 2>&1; then
    generator=(-G Ninja)
  fi
  local configure=(cmake -S "$ROOT/Benchmarks/gpu" -B "$BUILD" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release)
  if [ -n "$nvcc_path" ]; then
    configure+=("-DCMAKE_CUDA_COMPILER=$nvcc_path")
  fi
  if ! "${configure[@]}" "-DCMAKE_CUDA_ARCHITECTURES=$arch"; then
    if [ "$arch" != 90 ]; then
      echo "configure with CMAKE_CUDA_ARCHITECTURES=$arch failed: again with 90 in a fresh $BUILD"
      rm -rf "$BUILD"
      arch=90
      "${configure[@]}" "-DCMAKE_CUDA_ARCHITECTURES=$arch" || { echo "CONFIGURE FAILED"; return 1; }
    else
      echo "CONFIGURE FAILED"
      return 1
    fi
  fi
  section "build"
  local start=$SECONDS
  if ! timeout "$(left)" cmake --build "$BUILD" -j"$(nproc)"; then
    echo "BUILD FAILED"
    return 1
  fi
  echo "built in $((SECONDS - start)) s"

  section "GPU tests (vao_cuda_tests)"
  local test_binary
  test_binary="$(find "$BUILD/kernels" -name vao_cuda_tests -type f -perm -u+x 2>/dev/null | head -n1)"
  if [ -z "$test_binary" ]; then
    echo "GPU TESTS NOT BUILT: GoogleTest was not found (no package and no /usr/src/googletest);"
    echo "install libgtest-dev (or set VAO_GTEST_SOURCE_DIR) to build them"
    tests_built=0
  else
    start=$SECONDS
    local test_log="$BUILD/vao_cuda_tests.log" test_status=0
    timeout "$(left)" "$test_binary" --gtest_color=no >"$test_log" 2>&1 || test_status=$?
    cat "$test_log"
    skipped="$(sed -n 's/^\[  SKIPPED \] \([0-9]*\) tests\{0,1\}, listed below:$/\1/p' "$test_log" | head -n1)"
    skipped="${skipped:-0}"
    if [ "$test_status" -ne 0 ]; then
      echo "GPU TESTS FAILED (status $test_status) after $((SECONDS - start)) s"
      status=1
    elif [ "$skipped" -gt 0 ]; then
      echo "GPU TESTS SKIPPED: $skipped of them, no CUDA device ($(grep -m1 '^no CUDA device' "$test_log"))"
    else
      echo "GPU TESTS PASSED in $((SECONDS - start)) s"
    fi
    section "CPU kernel tests (ctest -L kernels)"
    start=$SECONDS
    local ctest_log="$BUILD/ctest_kernels.log"
    if (cd "$BUILD" && timeout "$(left)" ctest -L kernels -j"$(nproc)" --output-on-failure >"$ctest_log" 2>&1); then
      tail -n 4 "$ctest_log"
      echo "CPU KERNEL TESTS PASSED in $((SECONDS - start)) s"
    else
      tail -n 80 "$ctest_log"
      echo "CPU KERNEL TESTS FAILED"
      status=1
    fi
  fi

  section "GPU benchmark"
  start=$SECONDS
  local bench_status=0 bench_log="$BUILD/vao_gpu_benchmark.log"
  timeout "$(left)" "$BUILD/vao_gpu_benchmark" "$@" 2>&1 | tee "$bench_log"
  bench_status=${PIPESTATUS[0]}
  echo "benchmark exit status $bench_status after $((SECONDS - start)) s"
  if [ "$bench_status" -ne 0 ]; then
    echo "BENCHMARK FAILED"
    status=1
  fi

  section "summary"
  if [ "$status" -ne 0 ]; then
    echo "GPU checks: FAILED"
    return "$status"
  fi
  if [ "$skipped" -gt 0 ] || grep -q '^no CUDA device' "$bench_log"; then
    echo "GPU checks: NO CUDA DEVICE: the GPU tests skipped and the benchmark did not run"
    return 4
  fi
  if [ "$tests_built" -eq 0 ]; then
    echo "GPU checks: benchmark ran, tests NOT built (GoogleTest missing)"
    return 3
  fi
  echo "GPU checks: tests passed, benchmark ran (see its PASS/FAIL bars above)"
  return 0
}

cd "$ROOT" || exit 1
if [ -n "${OUT:-}" ]; then
  mkdir -p "$OUT"
  run_checks "$@" 2>&1 | tee "$OUT/gpu_checks.txt"
  exit "${PIPESTATUS[0]}"
fi
run_checks "$@" 2>&1
