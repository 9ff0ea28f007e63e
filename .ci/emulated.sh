#!/usr/bin/env bash
# Runs a command on qemu-user's model of an older processor (the kernel tests' emulated
# runs, Testing/CMakeLists.txt), unless this processor's own widest SIMD tier
# (CpuDispatch.h) is the model's: the native run of the same tests has then covered it,
# and the test reports itself skipped instead of taking a minute to repeat it.
#   bash .ci/emulated.sh QEMU MODEL command args...
set -euo pipefail
[ $# -gt 2 ] || { echo "usage: $0 QEMU MODEL command args..." >&2; exit 2; }
qemu="$1"
model="$2"
shift 2

has() { grep -qw "$1" /proc/cpuinfo; }
host=baseline
if has avx2 && has fma; then
  host=avx2
  if has avx512f && has avx512vl && has avx512dq && has avx512bw; then
    host=avx512
  fi
fi
case "$model" in
  Nehalem) tier=baseline ;;
  Haswell) tier=avx2 ;;
  *) tier=unknown ;;
esac
if [ "$host" = "$tier" ]; then
  echo "skipped: this processor's own SIMD tier is $tier, which the native kernel tests ran"
  exit 0
fi
exec "$qemu" -cpu "$model" "$@"
