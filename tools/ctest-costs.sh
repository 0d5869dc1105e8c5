#!/usr/bin/env bash
# Writes tests/ctest_costs.txt from a build folder's record of its last ctest runs (default
# build/, which should be a Release build whose whole suite has run): each test that ran,
# longest first, in ctest's own format. tools/run-tests.sh gives it to a new build folder so
# that ctest starts the longest tests first. Usage: tools/ctest-costs.sh [BUILD_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
record=${1:-build}/Testing/Temporary/CTestCostData.txt
[ -f "$record" ] || { echo "ctest-costs.sh: $record is missing: run ctest in that folder first" >&2; exit 1; }
# Lines "NAME RUNS COST" up to the line "---" (after it, the tests that failed last).
awk '$0 == "---" { exit } NF == 3 && $2 > 0 { printf "%s 1 %.1f\n", $1, $3 }' "$record" | sort -k3,3 -g -r >tests/ctest_costs.txt
echo "---" >>tests/ctest_costs.txt
echo "ctest-costs.sh: $(($(wc -l <tests/ctest_costs.txt) - 1)) tests in tests/ctest_costs.txt"
