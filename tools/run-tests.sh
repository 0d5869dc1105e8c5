#!/usr/bin/env bash
# The whole test suite: installs and builds what it needs, then runs ctest.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
# The Python package (docs/guide/python.md), which the pytest suites import from any folder.
# The sanitizer build leaves the package and those suites out (CMakeLists.txt).
case " ${PORTALSIM_CMAKE_ARGS:-} " in
  *PORTALSIM_SANITIZE=ON*) ;;
  *) bash tools/install-python.sh ;;
esac
# The browser test's driver (puppeteer-core, pinned by tests/browser/package-lock.json).
command -v npm >/dev/null || DEBIAN_FRONTEND=noninteractive apt-get install -y -q --no-install-recommends nodejs npm
(cd tests/browser && npm ci --no-audit --no-fund --loglevel=error)
src=$PWD
cd "${PORTALSIM_BUILD_DIR:-build}"
# A new build folder has no record of each test's time, so ctest would start the tests in the
# order they are declared, the longest (the bundle, the guides, the Python suites) among the
# last, with a core idle at the end; tests/ctest_costs.txt (tools/ctest-costs.sh) is a
# Release run's record, so the longest start first. ctest keeps its own record from then on.
costs=Testing/Temporary/CTestCostData.txt
[ -f "$costs" ] || { mkdir -p "${costs%/*}" && cp "$src/tests/ctest_costs.txt" "$costs"; }
ctest --output-on-failure -j "$(nproc)" "$@"
