#!/usr/bin/env bash
# The project against Debian 13 (trixie): ParaView 5.13, VTK 9.3/9.4. Builds a Debian 13
# root with debootstrap from Debian's own mirror (once; reused afterwards), copies this
# checkout into it (with the extra scans of ../shared/data when that folder exists), and runs the two set-up commands of the README there:
# `bash .ci/setup.sh test` (which installs the packages, builds and runs every test).
# Needs root. The first run downloads the Debian 13 root and its packages; later runs
# reuse them.
#
#   bash Testing/compat/debian13.sh [ROOT_DIR]      (default /var/tmp/vao-debian13)
set -euo pipefail
repo="$(cd "$(dirname "$0")/../.." && pwd)"
shared=""
[ -d "$repo/../shared/data" ] && shared="$(cd "$repo/../shared" && pwd)"
root="${1:-/var/tmp/vao-debian13}"
mirror="http://deb.debian.org/debian"

if [ "$(id -u)" -ne 0 ]; then
  echo "debian13.sh: needs root (debootstrap, chroot)" >&2
  exit 2
fi
command -v debootstrap >/dev/null || { apt-get update -qq && apt-get install -y -qq debootstrap; }

if [ ! -x "$root/usr/bin/apt-get" ]; then
  echo "== debootstrap trixie into $root"
  debootstrap --variant=minbase trixie "$root" "$mirror"
fi

mounted=()
cleanup() {
  for ((i = ${#mounted[@]} - 1; i >= 0; i--)); do umount -l "${mounted[i]}" 2>/dev/null || true; done
}
trap cleanup EXIT
for fs in proc sys dev dev/pts; do
  mkdir -p "$root/$fs"
  if ! mountpoint -q "$root/$fs"; then
    mount --bind "/$fs" "$root/$fs"
    mounted+=("$root/$fs")
  fi
done
cp /etc/resolv.conf "$root/etc/resolv.conf"

echo "== copying the checkout${shared:+ and $shared} (build trees left out)"
mkdir -p "$root/work/main"
# The last run's copy goes first (its build trees stay, for an incremental build): a file
# removed or moved since would otherwise remain there.
find "$root/work/main" -mindepth 1 -maxdepth 1 ! -name 'build*' -exec rm -rf {} +
tar -C "$repo" --exclude='./build*' --exclude='./vao-output' -cf - . | tar -C "$root/work/main" -xf -
if [ -n "$shared" ]; then
  mkdir -p "$root/work/shared"
  tar -C "$shared" -cf - . | tar -C "$root/work/shared" -xf -
fi

echo "== inside Debian 13: bash .ci/setup.sh test"
# Debian 13's ParaView CMake files (VTKPython-targets.cmake, ParaViewPython-targets.cmake)
# name the wrapped modules <module>.so, but python3-paraview ships them as
# <module>.cpython-3XX-<arch>.so: find_package(ParaView) stops on the missing files. The
# links below give CMake the names it checks (a packaging slip, not the project's).
chroot "$root" /usr/bin/env -i HOME=/root PATH=/usr/local/sbin:/usr/local/bin:/usr/sbin:/usr/bin:/sbin:/bin \
  LANG=C.UTF-8 bash -c 'set -e
    apt-get update -qq && apt-get install -y -qq --no-install-recommends ca-certificates sudo paraview-dev python3-paraview > /dev/null
    find /usr/lib/python3/dist-packages/vtkmodules /usr/lib/python3/dist-packages/paraview -name "*.cpython-3*-*.so" |
      while read -r f; do b="${f%%.cpython-*}.so"; [ -e "$b" ] || ln -s "$(basename "$f")" "$b"; done
    cd /work/main && grep -h VERSION_CODENAME /etc/os-release && bash .ci/setup.sh test'
