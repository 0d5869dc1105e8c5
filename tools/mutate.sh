#!/usr/bin/env bash
# Mutation testing of the kernels (issue 26): applies each mutation of LIST (default
# tools/mutations.txt) to kernels/*.cl, one at a time, and runs the suites that hold the
# kernels to an independent implementation. A mutation those tests catch is killed; one
# they pass is a survivor, reported with the list's reason. On demand only (not in CI:
# each mutation is a PoCL build of the program and a run of the suites).
#
#   tools/mutate.sh [BUILD_DIR] [LIST]     BUILD_DIR defaults to build
#   PORTALSIM_MUTATE_TESTS="F1 F2 ..."     the suites, as gtest filters tried in order
#   PORTALSIM_MUTATE_ONLY=N,M              run only these mutations (1-based)
#   PORTALSIM_MUTATE_BASELINE=0            skip the run on the unmutated kernels
#   PORTALSIM_MUTATE_WORK=DIR              its files (default BUILD_DIR/mutate): two runs
#                                          with their own DIR and ONLY can share a build
#
# Nothing is rebuilt per mutation and the work tree is never changed: the program (the
# files of CMakeLists.txt's PORTALSIM_KERNELS, in its order, joined as the build embeds
# them) is written with the mutation to WORK/program.cl, and
# PORTALSIM_KERNEL_PROGRAM makes the test binary, and each portalsim it starts, build that
# file instead of the built-in program. Each filter runs in one test process with
# --gtest_fail_fast, the cheap ones first, so a killed mutation stops at its first failing
# test; a mutation whose kernel PoCL cannot build is "invalid", not killed. PoCL's cache
# is WORK/pocl, emptied between mutations. Results go to
# WORK/results.tsv; the summary (kill rate, each survivor) to stdout. Exit
# status 0 once every mutation has been tried, whatever survived; 1 when the unmutated
# kernels fail.
set -euo pipefail
cd "$(dirname "$0")/.."
root=$(pwd)
build=$(realpath -m "${1:-build}")
list=$(realpath "${2:-tools/mutations.txt}")
# Cheap first: known answers and golden examples, then the parity suites, then the rest.
# (gtest runs a filter's tests in link order, so a filter is a stage.)
filters=${PORTALSIM_MUTATE_TESTS:-'Golden*:Philox*:Parity*:SparseFeatures*:Stages* Physics*:Metal* IrPhysics*:Camera.KernelsMatchTheReference Camera*:OpenCLPaths*:Extreme*:Baseline*:SubjectHeight*:RandomisedObjects*:Bodies*:Clothing*:RawGridDrawn*'}
py=/usr/bin/python3
work=$(realpath -m "${PORTALSIM_MUTATE_WORK:-$build/mutate}")
mkdir -p "$work"
export PORTALSIM_KERNEL_PROGRAM=$work/program.cl POCL_CACHE_DIR=$work/pocl

# program [FILE TEXT REPLACEMENT]: writes the program, with the mutation where one is given.
program() {
  "$py" "$root/tools/mutant_program.py" "$root" "$PORTALSIM_KERNEL_PROGRAM" "$@"
}

# Runs the filters in order; prints the first failing test ("invalid: ..." when PoCL could
# not build the program), or nothing when all pass.
run_suites() {
  local log=$work/test.log filter first
  for filter in $filters; do
    if timeout "${PORTALSIM_MUTATE_TIMEOUT:-1200}" "$build/portalsim_tests" --gtest_filter="$filter" \
      --gtest_fail_fast >"$log" 2>&1; then
      continue
    fi
    if grep -q "OpenCL program build failed" "$log"; then
      echo "invalid: PoCL cannot build the program"
      return 0
    fi
    first=$(grep -m1 -E '^\[  FAILED  \] [A-Za-z]' "$log" | sed 's/^\[  FAILED  \] //; s/ .*//' || true)
    echo "${first:-crash or timeout (see $log)}"
    return 0
  done
}

# Every mutation's text still in its file (ctest mutation_list), before an hour of runs.
"$py" "$root/tools/mutant_program.py" "$root" --check "$list" >/dev/null
echo "== building portalsim and portalsim_tests in $build"
cmake --build "$build" -j "${PORTALSIM_MUTATE_JOBS:-2}" --target portalsim_tests portalsim >"$work/build.log" 2>&1 ||
  { tail -30 "$work/build.log"; exit 1; }
if [ "${PORTALSIM_MUTATE_BASELINE:-1}" != 0 ]; then
  echo "== the suites on the unmutated kernels ($filters)"
  program
  rm -rf "$POCL_CACHE_DIR"
  start=$(date +%s)
  failed=$(run_suites)
  if [ -n "$failed" ]; then
    echo "the unmutated kernels fail $failed: fix that first"
    exit 1
  fi
  echo "   pass, $(($(date +%s) - start)) s"
fi

# The list: FILE<TAB>TEXT<TAB>REPLACEMENT<TAB>WHY, # comments. TEXT occurs once in FILE.
results=$work/results.tsv
printf 'n\tfile\tresult\ttest\twhy\n' >"$results"
n=0 killed=0 survived=0 invalid=0
only=",${PORTALSIM_MUTATE_ONLY:-},"
while IFS=$'\t' read -r -u 3 file text replacement why; do
  [ -z "$file" ] || [ "${file:0:1}" = "#" ] && continue
  n=$((n + 1))
  [ "$only" = ",," ] || [[ "$only" == *",$n,"* ]] || continue
  program "$file" "$text" "$replacement"
  rm -rf "$POCL_CACHE_DIR"
  start=$(date +%s)
  test=$(run_suites)
  if [ -z "$test" ]; then
    result=survived test=- survived=$((survived + 1))
  elif [[ "$test" == invalid:* ]]; then
    result=invalid test=${test#invalid: } invalid=$((invalid + 1))
  else
    result=killed killed=$((killed + 1))
  fi
  printf '%s\t%s\t%s\t%s\t%s\n' "$n" "$file" "$result" "$test" "$why" >>"$results"
  printf '%3d %-28s %-9s %-55s %ds\n' "$n" "$file" "$result" "$test" "$(($(date +%s) - start))"
done 3<"$list"
rm -rf "$POCL_CACHE_DIR" "$PORTALSIM_KERNEL_PROGRAM"

tried=$((killed + survived))
echo "== $killed of $tried mutations killed ($((tried ? 100 * killed / tried : 0))%), $survived survived, $invalid invalid"
awk -F'\t' '$3 == "survived" { printf "survivor %s (%s): %s\n", $1, $2, $5 }' "$results"
awk -F'\t' '$3 == "invalid" { printf "invalid %s (%s): %s\n", $1, $2, $4 }' "$results"
