#!/usr/bin/env bash
# Installs portalsim's Debian 12 packages (as root, apt-get update first) and builds
# it into build/ (Release). Safe to run again: it only installs what is missing and
# rebuilds what changed.
set -euo pipefail
cd "$(dirname "$0")/.."

source tools/packages.sh
bash tools/apt-install.sh "${core_packages[@]}" "${python_packages[@]}" "${tool_packages[@]}"

build_dir=${PORTALSIM_BUILD_DIR:-build}
# A new build folder uses Ninja (it runs the test files' compiles beside the library's);
# one configured before keeps its generator.
generator=()
[ -f "$build_dir/CMakeCache.txt" ] || ! command -v ninja >/dev/null || generator=(-G Ninja)
cmake -S . -B "$build_dir" "${generator[@]}" -DCMAKE_BUILD_TYPE=Release ${PORTALSIM_CMAKE_ARGS:-} >/dev/null
# PORTALSIM_TARGET builds one target (the main job needs only portalsim).
cmake --build "$build_dir" -j "$(nproc)" ${PORTALSIM_TARGET:+--target "$PORTALSIM_TARGET"}
