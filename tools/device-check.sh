#!/usr/bin/env bash
# Checks an OpenCL device (a GPU) with the unpacked bundle, in about 5 minutes, writing to OUTDIR:
#   devices.txt     the OpenCL platforms and devices, and the machine;
#   compare.tsv     data sets (features and images; models thesis and physics; tiers fast,
#                   standard, exact) made on the device against the same made on a CPU
#                   OpenCL device (if there is one) and on the fp64 reference, byte for byte;
#   tradeoff/       `portalsim tradeoff`: every tier against the fp64 reference, with
#                   within_tolerance per model and tier (host/plan/tolerance.h);
#   bench.json      `portalsim bench --json` on the device;
#   summary.txt     the above in a few lines, and each step's seconds.
# Exits 1 if a run fails or a tier is outside its tolerance. Byte differences between devices
# are reported, not failed: the kernels' contract is the tolerance against the reference
# (docs/model/tiers.md). docs/guide/install.md has more.
# Usage: device-check.sh OUTDIR [DEVICE]
#   DEVICE: a substring, in any case, of a name `portalsim bench --list-devices` prints (default: the first
#   gpu device). PORTALSIM overrides the binary (default: bin/portalsim beside this tools/).
#   FEATURES_COUNT (2048), IMAGES_COUNT (64), TRADEOFF_COUNT (400), BENCH_SECONDS (150) size it.
set -euo pipefail
fail() { echo "device-check: $*" >&2; exit 1; }
trap '[[ $- != *e* ]] || echo "device-check: stopped by a failing command at line $LINENO" >&2' ERR
[ $# -ge 1 ] && [ $# -le 2 ] || fail "usage: device-check.sh OUTDIR [DEVICE]"
out=$(realpath -m "$1")
want=${2:-}
here=$(cd "$(dirname "$0")" && pwd)
ps=${PORTALSIM:-$here/../bin/portalsim}
[ -x "$ps" ] || fail "no portalsim at $ps (run this from the unpacked bundle, or set PORTALSIM)"
features_count=${FEATURES_COUNT:-2048}
images_count=${IMAGES_COUNT:-64}
tradeoff_count=${TRADEOFF_COUNT:-400}
bench_seconds=${BENCH_SECONDS:-150}
mkdir -p "$out"
[ -z "$(ls -A "$out")" ] || fail "$out is not empty; choose a new folder"
summary=$out/summary.txt
say() { echo "$*" | tee -a "$summary"; }
failed=0
t0=$SECONDS
step() { say "[$((SECONDS - t0)) s] $*"; }

# The machine and its devices.
{
  echo "portalsim: $("$ps" --version)"
  echo "host: $(uname -srm), $(nproc) cores; $(ldd --version 2>&1 | head -n1)"
  echo "OCL_ICD_VENDORS=${OCL_ICD_VENDORS:-(unset)}"
  echo "/etc/OpenCL/vendors: $(ls /etc/OpenCL/vendors 2>/dev/null | tr '\n' ' ')"
  if command -v nvidia-smi >/dev/null; then nvidia-smi -L 2>&1 || true; fi
  if command -v clinfo >/dev/null; then clinfo -l 2>&1 || true; fi
  echo
  echo "portalsim bench --list-devices:"
} >"$out/devices.txt"
devices=$("$ps" bench --list-devices 2>&1) || { echo "$devices" >>"$out/devices.txt"; fail "bench --list-devices failed: $devices"; }
echo "$devices" >>"$out/devices.txt"
# Lines are "platform / device<TAB>type, N compute units, fp64 yes|no".
if [ -n "$want" ]; then
  line=$(grep -i -F -- "$want" <<<"$devices" | head -n1 || true)  # any case: "pocl", "nvidia"
  [ -n "$line" ] || fail "no device matches '$want'; the devices are:"$'\n'"$devices"
else
  line=$(awk -F'\t' '$2 ~ /^gpu/' <<<"$devices" | head -n1)
  [ -n "$line" ] || fail "no gpu device among:"$'\n'"$devices"$'\n'"(name one as DEVICE to check another)"
fi
device=${line%%$'\t'*}
fp64=yes
[[ $line == *"fp64 yes"* ]] || fp64=no
cpu=$(awk -F'\t' '$2 ~ /^cpu/ {print $1}' <<<"$devices" | grep -v -x -F -- "$device" | head -n1 || true)
step "device: $device (fp64 $fp64); compared with: ${cpu:+the CPU device $cpu and }the fp64 reference"

# The data sets. Without fp64 the exact tier and the physics model's metal detector cannot run
# on the device (docs/guide/bench.md): those are left out and said so.
printf 'model\ttier\twhat\tagainst\tfile\tbytes\tbytes_differing\tmax_level_difference\n' >"$out/compare.tsv"
compare() {  # compare DIR_A DIR_B LABEL MODEL TIER WHAT
  local f name dtype n diff maxd
  for f in "$1"/*.npy; do
    name=$(basename "$f")
    [ -f "$2/$name" ] || { say "  $4 $5 $6: $name missing from $3"; failed=1; continue; }
    n=$(stat -c %s "$f")
    diff=$(cmp -l "$f" "$2/$name" 2>/dev/null | wc -l || true)
    [ "$(stat -c %s "$2/$name")" = "$n" ] || diff="size $(stat -c %s "$2/$name")"
    maxd=-
    dtype=$(head -c 128 "$f" | tr -d '\0' | grep -a -o "'descr': '[^']*'" | head -n1 || true)
    if [[ $dtype == *"|u1"* ]] && [[ $diff =~ ^[0-9]+$ ]] && [ "$diff" -gt 0 ]; then
      maxd=$(cmp -l "$f" "$2/$name" | awk 'function o(s,  v, i) {for (i = 1; i <= length(s); i++) v = v * 8 + substr(s, i, 1); return v} {d = o($2) - o($3); if (d < 0) d = -d; if (d > m) m = d} END {print m + 0}' || true)
    fi
    printf '%s\t%s\t%s\t%s\t%s\t%s\t%s\t%s\n' "$4" "$5" "$6" "$3" "$name" "$n" "$diff" "$maxd" >>"$out/compare.tsv"
  done
}
gen() {  # gen DIR MODEL TIER WHAT BACKEND-ARGS...
  local dir=$1 model=$2 tier=$3 what=$4 count=$features_count
  shift 4
  [ "$what" = features ] || count=$images_count
  "$ps" generate --model "$model" --tier "$tier" --what "$what" --format npy --count "$count" --seed 11 \
    --pixel-noise 2 --quiet --out "$dir" "$@" >"$dir.log" 2>&1
}
for model in thesis physics; do
  for tier in fast standard exact; do
    for what in features images; do
      d=$out/data/$model-$tier-$what
      mkdir -p "$out/data"
      if [ "$fp64" = no ] && { [ "$tier" = exact ] || [ "$model" = physics ]; }; then
        say "  $model $tier $what: left out (the device has no fp64)"
        continue
      fi
      gen "$d.device" "$model" "$tier" "$what" --device "$device" ||
        { say "  $model $tier $what: FAILED on the device ($d.device.log)"; failed=1; continue; }
      gen "$d.reference" "$model" "$tier" "$what" --backend reference ||
        { say "  $model $tier $what: FAILED on the reference ($d.reference.log)"; failed=1; continue; }
      compare "$d.device" "$d.reference" reference "$model" "$tier" "$what"
      if [ -n "$cpu" ]; then
        gen "$d.cpu" "$model" "$tier" "$what" --device "$cpu" ||
          { say "  $model $tier $what: FAILED on the CPU device ($d.cpu.log)"; failed=1; continue; }
        compare "$d.device" "$d.cpu" cpu "$model" "$tier" "$what"
      fi
    done
  done
done
identical=$(awk -F'\t' 'NR > 1 && $7 == "0"' "$out/compare.tsv" | wc -l)
total=$(($(wc -l <"$out/compare.tsv") - 1))
step "data sets: $identical of $total files byte-identical (compare.tsv; the rest differ within the tiers' tolerances or not: see tradeoff)"
awk -F'\t' 'NR > 1 && $7 != "0" {printf "  differ: %s %s %s vs %s: %s: %s of %s bytes, max level difference %s\n", $1, $2, $3, $4, $5, $7, $6, $8}' \
  "$out/compare.tsv" | tee -a "$summary"

# The kernels against the fp64 reference, per model and tier.
models=thesis,physics
[ "$fp64" = yes ] || models=thesis
if "$ps" tradeoff --device "$device" --count "$tradeoff_count" --models "$models" --no-classifier --no-plot \
  --out "$out/tradeoff" >"$out/tradeoff.log" 2>&1; then
  col=$(head -n1 "$out/tradeoff/tradeoff.csv" | tr ',' '\n' | grep -n -x within_tolerance | cut -d: -f1)
  outside=$(awk -F, -v c="$col" 'NR > 1 && $c != "yes" {print $1 " " $2}' "$out/tradeoff/tradeoff.csv")
  if [ -n "$outside" ]; then
    failed=1
    step "tradeoff: OUTSIDE the tolerance: $(echo $outside)"
  else
    step "tradeoff: every model and tier within its tolerance against the fp64 reference (tradeoff/tradeoff.csv)"
  fi
else
  failed=1
  step "tradeoff: FAILED ($out/tradeoff.log)"
fi

# The speed table on the device; if the full run does not fit the time, the quick one.
bench_dir=$(mktemp -d)
set +e
timeout "$bench_seconds" "$ps" bench --device "$device" --json --repetitions 1 --dir "$bench_dir" \
  >"$out/bench.json" 2>"$out/bench.log"
rc=$?
if [ $rc = 124 ]; then
  step "bench: the full run took over $bench_seconds s; running --quick (not a measurement)"
  "$ps" bench --device "$device" --json --quick --dir "$bench_dir" >"$out/bench.json" 2>"$out/bench.log"
  rc=$?
fi
set -e
rm -rf "$bench_dir"
if [ $rc = 0 ]; then step "bench: bench.json (bench.log: its table notes)"; else failed=1; step "bench: FAILED (exit $rc, bench.log)"; fi

rm -rf "$out/data"  # the tables keep the comparison; the data sets are large
if [ $failed = 0 ]; then step "device-check: passed"; else step "device-check: FAILED (see above)"; fi
exit $failed
