#!/usr/bin/env bash
# The C++ and CUDA sources against .clang-format (clang-format 16): lists the files that
# differ and exits 1; with --fix, formats them in place.
set -euo pipefail
cd "$(dirname "$0")/.."
format=clang-format-16
command -v "$format" >/dev/null || { echo "$format is missing: bash .ci/setup.sh format installs it" >&2; exit 2; }
mapfile -t files < <(git ls-files -- '*.h' '*.cxx' '*.cu')
if [ "${1:-}" = --fix ]; then
  "$format" -i "${files[@]}"
  echo "== formatted ${#files[@]} files"
  exit 0
fi
if ! "$format" --dry-run --Werror "${files[@]}" 2>/tmp/vao-format.$$; then
  grep -o '^[^:]*\.\(h\|cxx\|cu\):' /tmp/vao-format.$$ | sort -u | sed 's/:$//; s/^/  not formatted: /'
  rm -f /tmp/vao-format.$$
  echo "== run: bash .ci/setup.sh format --fix" >&2
  exit 1
fi
rm -f /tmp/vao-format.$$
echo "== ${#files[@]} C++ and CUDA sources follow .clang-format"
