#!/usr/bin/env bash
# Runs every libFuzzer target for SECONDS (default 50) from the seed corpus in
# tests/fuzz/corpus/TARGET, in a scratch copy (the checkout is not written). Builds
# build-fuzz/ with clang first. Exits non-zero on the first crash, leaving the input in
# build-fuzz/crashes/TARGET/; add it to tests/fuzz/crashes/TARGET/ as a regression.
set -euo pipefail
cd "$(dirname "$0")/../.."
seconds=${1:-50}
generator=()
[ -f build-fuzz/CMakeCache.txt ] || ! command -v ninja >/dev/null || generator=(-G Ninja)
CC=clang CXX=clang++ cmake -S . -B build-fuzz "${generator[@]}" -DCMAKE_BUILD_TYPE=RelWithDebInfo -DPORTALSIM_FUZZ=ON \
  -DPORTALSIM_TESTS=OFF -DPORTALSIM_BENCH=OFF ${PORTALSIM_CMAKE_ARGS:-} >/dev/null
targets=(catalogue spec scenarios feature_table image arff csv h5 checkpoint manifest request)
cmake --build build-fuzz -j "$(nproc)" --target "${targets[@]/#/fuzz_}"
# One target per core at a time; each prints its stats when it ends.
fuzz_one() {
  local target=$1 seconds=$2
  local work=build-fuzz/corpus/$target crashes=build-fuzz/crashes/$target
  rm -rf "$work" && mkdir -p "$work" "$crashes"
  if ! ASAN_OPTIONS=detect_leaks=0 build-fuzz/fuzz_$target -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 \
    -max_len=65536 -artifact_prefix="$crashes/" -print_final_stats=1 "$work" "tests/fuzz/corpus/$target" \
    2>build-fuzz/fuzz_$target.log; then
    echo "== fuzz_$target failed:"
    tail -40 build-fuzz/fuzz_$target.log
    return 1
  fi
  echo "== fuzz_$target, $seconds s: $(grep -E "^stat::number_of_executed_units|^stat::average_exec_per_sec" \
    build-fuzz/fuzz_$target.log | tr -s ' ' | tr '\n' ' ')"
}
export -f fuzz_one
printf '%s\n' "${targets[@]}" | xargs -P "$(nproc)" -I{} bash -c 'fuzz_one "$1" "$2"' _ {} "$seconds"
