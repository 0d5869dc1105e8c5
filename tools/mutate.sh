#!/usr/bin/env bash
# Mutation testing of the kernels (issue 26): applies each mutation of LIST (default
# tools/mutations.txt) to kernels/*.cl, one at a time, in a copy of the checkout, rebuilds
# and runs the suites that hold the kernels to an independent implementation. A mutation
# those tests catch is killed; one they pass is a survivor, reported with the list's
# reason. On demand only (not in CI: each mutation is a relink and a run of the suites).
#
#   tools/mutate.sh [BUILD_DIR] [LIST]     BUILD_DIR defaults to build-mutate
#   PORTALSIM_MUTATE_TESTS=GTEST_FILTER    the suites (default below)
#   PORTALSIM_MUTATE_ONLY=N,M              run only these mutations (1-based)
#
# The work tree is never changed: BUILD_DIR/src is the copy that gets mutated, built in
# BUILD_DIR/src/build (ccache makes its first build cheap after a normal one). The suites
# run in one test process (--gtest_fail_fast), so that each mutated kernel program is
# compiled once, and a killed mutation stops at its first failing test. Results go to
# BUILD_DIR/results.tsv; the summary (kill rate, each survivor) to stdout. Exit status 0
# once every mutation has been tried, whatever survived; 1 when the unmutated kernels fail.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
build=$(realpath -m "${1:-build-mutate}")
list=$(realpath "${2:-tools/mutations.txt}")
filter=${PORTALSIM_MUTATE_TESTS:-'Parity*:Physics*:IrPhysics*:Extreme*:Metal*:Stages*:SparseFeatures*:Baseline*:SubjectHeight*:RandomisedObjects*'}
py=/usr/bin/python3
copy=$build/src
mkdir -p "$copy"

# The copy: tracked and new files of the work tree as they are now.
git ls-files -z -co --exclude-standard | xargs -0 cp --parents -t "$copy/"
cmake -S "$copy" -B "$copy/build" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPORTALSIM_BENCH=OFF >/dev/null

build_once() { cmake --build "$copy/build" -j "${PORTALSIM_MUTATE_JOBS:-2}" --target portalsim_tests portalsim >"$build/build.log" 2>&1; }
# Runs the suites; prints the first failing test, or nothing when all pass.
run_suites() {
  local log=$build/test.log
  if timeout "${PORTALSIM_MUTATE_TIMEOUT:-900}" "$copy/build/portalsim_tests" --gtest_filter="$filter" \
    --gtest_fail_fast >"$log" 2>&1; then
    return 0
  fi
  local first
  first=$(grep -m1 -E '^\[  FAILED  \] [A-Za-z]' "$log" | sed 's/^\[  FAILED  \] //; s/ .*//' || true)
  echo "${first:-crash or timeout (see $log)}"
}

echo "== building the unmutated copy in $copy/build"
build_once || { tail -30 "$build/build.log"; exit 1; }
echo "== the suites on the unmutated kernels ($filter)"
start=$(date +%s)
failed=$(run_suites || true)
if [ -n "$failed" ]; then
  echo "the unmutated kernels fail $failed: fix that first"
  exit 1
fi
echo "   pass, $(($(date +%s) - start)) s"

# The list: FILE<TAB>TEXT<TAB>REPLACEMENT<TAB>WHY, # comments. TEXT occurs once in FILE.
apply() {  # apply FILE TEXT REPLACEMENT: in the copy
  "$py" - "$copy/$1" "$2" "$3" <<'EOF'
import sys
path, old, new = sys.argv[1:]
text = open(path).read()
n = text.count(old)
if n != 1:
    sys.exit(f"{path}: the mutation's text occurs {n} times (must be once): {old}")
open(path, "w").write(text.replace(old, new))
EOF
}

results=$build/results.tsv
printf 'n\tfile\tresult\ttest\twhy\n' >"$results"
n=0 killed=0 survived=0
only=",${PORTALSIM_MUTATE_ONLY:-},"
while IFS=$'\t' read -r file text replacement why; do
  [ -z "$file" ] || [ "${file:0:1}" = "#" ] && continue
  n=$((n + 1))
  [ "$only" = ",," ] || [[ "$only" == *",$n,"* ]] || continue
  apply "$file" "$text" "$replacement"
  start=$(date +%s)
  if ! build_once; then
    result=invalid test="does not build"
  else
    test=$(run_suites || true)
    if [ -n "$test" ]; then result=killed; killed=$((killed + 1)); else result=survived test=-; survived=$((survived + 1)); fi
  fi
  cp "$root/$file" "$copy/$file"
  printf '%s\t%s\t%s\t%s\t%s\n' "$n" "$file" "$result" "$test" "$why" >>"$results"
  printf '%3d %-28s %-9s %-50s %ds\n' "$n" "$file" "$result" "$test" "$(($(date +%s) - start))"
done <"$list"
build_once  # leave the copy's binaries unmutated

tried=$((killed + survived))
echo "== $killed of $tried mutations killed ($((tried ? 100 * killed / tried : 0))%), $survived survived"
awk -F'\t' '$3 == "survived" { printf "survivor %s (%s): %s\n", $1, $2, $5 }' "$results"
awk -F'\t' '$3 == "invalid" { printf "invalid %s (%s): does not build\n", $1, $2 }' "$results"
