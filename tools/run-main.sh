#!/usr/bin/env bash
# The main job on the built-in catalogue: installs and builds what it needs, installs
# portalsim onto the PATH (PREFIX, /usr/local by default), then makes the thesis's two
# experimental data sets (chapter 6) with portalsim generate, scores each with WEKA's J48
# decision tree under 10-fold cross-validation, and simulates the thesis's worked example
# (a gun in the right abdomen) under the thesis's model and the physics model. Everything
# lands in out/.
set -euo pipefail
cd "$(dirname "$0")/.."
PORTALSIM_TARGET=portalsim bash tools/setup.sh
prefix=${PREFIX:-/usr/local}
cmake --install "${PORTALSIM_BUILD_DIR:-build}" --component cli --prefix "$prefix"
# A PREFIX whose bin/ is not on the PATH still runs the binary just installed.
export PATH="$prefix/bin:$PATH"
echo "== $(command -v portalsim): $(portalsim --version)"
rm -rf out && mkdir -p out
portalsim simulate none none none gun --rule gun --out out/gun --timing
portalsim simulate --model physics none none none gun --rule gun --out out/gun-physics --timing
cases=(case1-gun case2-rod-plate)
for case in "${cases[@]}"; do
  portalsim generate --spec "scenarios/$case.toml" --out "out/$case" --timing
done
# WEKA's J48 runs on one core (two minutes for case 1 here): the cases' cross-validations
# run side by side, each report kept as out/CASE/j48.txt, and their accuracies are printed
# in order.
pids=()
for case in "${cases[@]}"; do
  java -Xmx4g -cp /usr/share/java/weka.jar weka.classifiers.trees.J48 -t "out/$case/features.arff" -o \
    >"out/$case/j48.txt" &
  pids+=($!)
done
for i in "${!cases[@]}"; do
  if ! wait "${pids[i]}"; then
    echo "run-main.sh: WEKA's J48 failed on out/${cases[i]}/features.arff" >&2
    kill "${pids[@]}" 2>/dev/null || true
    exit 1
  fi
  echo "== WEKA J48, 10-fold cross-validation, out/${cases[i]}/features.arff"
  grep -A2 "Stratified cross-validation" "out/${cases[i]}/j48.txt" | tail -1
done
