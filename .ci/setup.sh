#!/usr/bin/env bash
# One set-up for every use of the project on a fresh Debian 12 machine: install the
# Debian packages that are missing, configure and build (build/), then run one job:
#
#   bash .ci/setup.sh demo [vao-demo arguments]   the main job (AO of the generated phantom
#                                                 or of a file you name; see README.md)
#   bash .ci/setup.sh test                        the whole test suite (ctest)
#   bash .ci/setup.sh benchmark                   the benchmark table (docs/performance.md)
#   bash .ci/setup.sh build                       set-up only
#   bash .ci/setup.sh sanitize [--filters]        the tests under ASan + UBSan and TSan
#   bash .ci/setup.sh fuzz [seconds]              libFuzzer on the kernel library (600 s)
#   bash .ci/setup.sh format [--fix]              the C++ sources against .clang-format
set -euo pipefail
cd "$(dirname "$0")/.."
job="${1:-demo}"
shift || true

# Verified from a bare (minbase) Debian 12: ParaView's development files and what its CMake
# files ask for, plus scipy for the benchmark's peer, python3-dev for the Python package and
# qemu-user for the kernel tests on an emulated processor without AVX2. docs/development.md
# says which of them a plain CMake build needs.
qt_packages=(qtbase5-dev qttools5-dev libqt5svg5-dev libqt5opengl5-dev qtxmlpatterns5-dev-tools
  libqt5x11extras5-dev)
# Debian 13's ParaView 5.13 is built with Qt 6 (Testing/compat/debian13.sh runs this there).
if grep -qs '^VERSION_CODENAME=trixie' /etc/os-release; then
  qt_packages=(qt6-base-dev qt6-tools-dev qt6-svg-dev qt6-5compat-dev libqt6opengl6-dev)
fi
packages=(cmake g++ ninja-build paraview-dev paraview python3-paraview "${qt_packages[@]}"
  libhdf5-openmpi-dev libutfcpp-dev libgl2ps-dev libglew-dev libgdal-dev libnetcdf-dev
  libavcodec-dev libavformat-dev libswscale-dev libtheora-dev libdouble-conversion-dev
  liblz4-dev libexpat1-dev libeigen3-dev libboost-dev libfreetype-dev mpi-default-dev
  python3-mpi4py libgtest-dev xvfb xauth python3-numpy python3-scipy python3-dev python3-tqdm qemu-user
  valgrind)
# libFuzzer comes with clang (GCC's sanitizers come with g++).
[ "$job" = fuzz ] && packages+=(clang-16 libclang-rt-16-dev)
# The formatter at the version .clang-format is written for (git lists the sources).
[ "$job" = format ] && packages=(clang-format-16 git)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "== installing ${#missing[@]} missing Debian packages: ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

case "$job" in
  sanitize) exec bash .ci/sanitize.sh "$@" ;;
  fuzz) exec bash .ci/fuzz.sh "$@" ;;
  format) exec bash .ci/format.sh "$@" ;;
esac

echo "== configuring and building (build/)"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release
cmake --build build -j "$(nproc)"

case "$job" in
  demo)
    build/bin/vao-demo "$@"
    # The figures of the papers (volume rendering, isosurfaces) with every filter, on the
    # CT head phantom the repository ships (Data/).
    ct=Data/ct_head_phantom/ct_head_phantom_128x128x136_int16.mha
    exec bash .ci/with-xvfb.sh /usr/bin/pvpython --force-offscreen-rendering \
      Examples/figures.py "$(cat build/VolumetricAOPluginPath.txt)" vao-output/figures $ct ;;
  test)
    # Open MPI refuses to run as root without these (the MPI tests add the flags too).
    export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1
    cd build && exec ctest --output-on-failure -j "$(nproc)" "$@" ;;
  benchmark)
    exec build/bin/vao_benchmark "$@" ;;
  build)
    ;;
  *)
    echo "unknown job '$job' (demo, test, benchmark, build, sanitize, fuzz, format)" >&2
    exit 2 ;;
esac
