#!/usr/bin/env bash
# Fuzzes every entry point of the kernel library (CUDA/tests/fuzz/FuzzEntryPoints.h says
# what is checked) with libFuzzer, under AddressSanitizer and UndefinedBehaviorSanitizer
# (float-cast-overflow included), for N seconds (default 600). Needs clang-16 and
# libclang-rt-16-dev: run it as `bash .ci/setup.sh fuzz [seconds]`, which installs them.
# Findings are written as crash-* files in build-fuzz/ and make the script fail.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-600}"
flags="-fsanitize=fuzzer-no-link,address,undefined,float-cast-overflow"
flags+=" -fno-sanitize-recover=undefined,float-cast-overflow -fno-omit-frame-pointer -g"
cmake -S CUDA -B build-fuzz -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_CXX_COMPILER=clang++-16 \
  -DCMAKE_CXX_FLAGS="$flags" -DVAO_ENABLE_CUDA=OFF -DVAO_BUILD_FUZZER=ON -DBUILD_TESTING=ON
cmake --build build-fuzz --target vao_fuzz
mkdir -p build-fuzz/corpus
cd build-fuzz
exec ./tests/vao_fuzz -max_total_time="$seconds" -timeout=120 -rss_limit_mb=6144 -max_len=8192 -len_control=0 \
  -print_final_stats=1 corpus
