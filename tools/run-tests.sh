#!/usr/bin/env bash
# The whole test suite: installs and builds what it needs, then runs ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
cd "${PORTALSIM_BUILD_DIR:-build}"
ctest --output-on-failure -j "$(nproc)" "$@"
