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
for case in case1-gun case2-rod-plate; do
  portalsim generate --spec "scenarios/$case.toml" --out "out/$case" --timing
  echo "== WEKA J48, 10-fold cross-validation, out/$case/features.arff"
  java -Xmx4g -cp /usr/share/java/weka.jar weka.classifiers.trees.J48 -t "out/$case/features.arff" -o \
    | grep -A2 "Stratified cross-validation" | tail -1 || true
done
