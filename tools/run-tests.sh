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
cd "${PORTALSIM_BUILD_DIR:-build}"
ctest --output-on-failure -j "$(nproc)" "$@"
