#!/usr/bin/env bash
# Installs portalsim's Debian 12 packages (as root, apt-get update first) and builds
# it into build/ (Release). Safe to run again: it only installs what is missing and
# rebuilds what changed.
set -euo pipefail
cd "$(dirname "$0")/.."

packages=(build-essential cmake ninja-build pkg-config
  pocl-opencl-icd ocl-icd-opencl-dev opencl-headers opencl-clhpp-headers clinfo
  libopenimageio-dev openimageio-tools
  libcli11-dev libtomlplusplus-dev nlohmann-json3-dev
  libxxhash-dev libisal-dev libgtest-dev libbenchmark-dev libcpp-httplib-dev libhdf5-dev libboost-dev
  openmpi-bin libopenmpi-dev slurm-wlm munge
  weka default-jdk-headless python3 python3-matplotlib python3-scipy python3-h5py python3-numpy python3-torch
  python3-pyld python3-yaml
  python3-dev pybind11-dev python3-pybind11 python3-pytest python3-pil
  clang-format ccache
  clang libclang-rt-14-dev chromium)

bash tools/apt-install.sh "${packages[@]}"

build_dir=${PORTALSIM_BUILD_DIR:-build}
# A new build folder uses Ninja (it runs the test files' compiles beside the library's);
# one configured before keeps its generator.
generator=()
[ -f "$build_dir/CMakeCache.txt" ] || ! command -v ninja >/dev/null || generator=(-G Ninja)
cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release ${PORTALSIM_CMAKE_ARGS:-} >/dev/null
# PORTALSIM_TARGET builds one target (the main job needs only portalsim).
cmake --build "$build_dir" -j "$(nproc)" ${PORTALSIM_TARGET:+--target "$PORTALSIM_TARGET"}
