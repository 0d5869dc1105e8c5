#!/usr/bin/env bash
# Makes every figure and screenshot in docs/ from portalsim's own outputs, one command:
#
#   bash tools/make-docs-figures.sh [BUILD_DIR] [FIGURE ...]
#
# BUILD_DIR holds the portalsim binary (default build/, as tools/setup.sh makes it).
# Without FIGURE names it makes them all; the names are the functions below. Needs
# /usr/bin/python3 with matplotlib, and for the page's screenshot node, puppeteer-core
# (tests/browser/, installed by tools/run-tests.sh) and Chromium. `tradeoff` and
# `sensitivity` and `evaluate` take minutes: they train classifiers on thousands of scenarios.
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build}
[ $# -gt 0 ] && shift
portalsim=$PWD/$build/portalsim
[ -x "$portalsim" ] || { echo "make-docs-figures: no portalsim in $build/ (run tools/setup.sh)" >&2; exit 2; }
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
py=/usr/bin/python3

# The README's two models side by side, and one row through the physics chain.
models() { "$py" tools/physics_figures.py "$portalsim" docs/; }
# README and docs/reference/catalogue.md: the front-and-back portal's views and regions.
portal() { "$py" tools/plot_portal_views.py "$portalsim" docs/portal_front_back.png; }
# docs/model/subjects.md: the subjects at three heights.
subjects() { "$py" tools/plot_subject_heights.py "$portalsim" docs/subject_heights.png; }
# docs/model/randomised-objects.md: turned, scaled and mirrored objects.
randomised() { "$py" tools/plot_randomised_objects.py "$portalsim" docs/randomised_objects.png; }
# docs/guide/deep-learning.md: a COCO box and the masks decoded from its RLE.
coco() {
  "$portalsim" generate --count 40 --seed 3 --what images --objects 5..8 --jitter 40 --annotations \
    --quiet --out "$work/set"
  "$py" tools/plot_coco_box.py "$work/set" docs/coco_box.png
}
# docs/guide/calibrate.md: the report's plot of the guide's own example.
calibrate() {
  "$portalsim" generate --model physics --what images --count 16 --seed 1 --quiet --out "$work/captures"
  "$portalsim" calibrate --real "$work/captures" --out "$work/camera.toml" > /dev/null
  cp "$work/camera-report/calibrate.png" docs/guide/calibrate.png
}
# docs/guide/serve.md: the page in headless Chromium, as the browser test drives it.
serve() { node tests/browser/serve_models.test.mjs "$portalsim" "$work/serve" "$PWD/docs/serve.png"; }
# docs/model/physics-mmw.md: J48 accuracy against frames and NETD (minutes).
sensitivity() { "$py" tools/physics_sensitivity.py "$portalsim" docs/physics_sensitivity.png; }
# docs/model/tiers.md: throughput against error per fidelity tier (about 8 minutes).
tradeoff() {
  "$portalsim" tradeoff --out "$work/trade"
  cp "$work/trade/tradeoff.png" docs/tradeoff.png
  cp "$work/trade/tradeoff.csv" docs/tradeoff.csv
}
# docs/guide/metal-map.md: the gun's metal detector sensitivity map (seconds).
metalmap() {
  "$portalsim" evaluate --metal-map gun --out "$work/metalmap" > /dev/null
  cp "$work/metalmap/metal_map.png" docs/guide/metal-map.png
}

# docs/guide/evaluate.md: the example study, 27 settings of the MMW camera x 5,000
# scenarios of case 2's objects (about 5 minutes on 2 cores), and one setting's report.
evaluate() {
  "$portalsim" evaluate --spec scenarios/study-case2-mmw-metal.toml \
    --sweep "netd=1,2,3 mmw_raw=16x16,28x28,56x56 frames=1,4,10" --out "$work/study" > /dev/null
  cp "$work/study/sweep.png" docs/evaluate_study_sweep.png
  cp "$work/study/sweep.csv" docs/evaluate_study_sweep.csv
  "$portalsim" evaluate --spec scenarios/study-case2-mmw-metal.toml --netd 1 --mmw-raw 56x56 --frames 10 \
    --out "$work/one" > /dev/null
  cp "$work/one/roc.png" docs/evaluate_study_roc.png
  cp "$work/one/regions.png" docs/evaluate_study_regions.png
}

all=(models portal subjects randomised coco calibrate serve sensitivity tradeoff metalmap evaluate)
for figure in "${@:-${all[@]}}"; do
  case " ${all[*]} " in
    *" $figure "*) ;;
    *) echo "make-docs-figures: no figure '$figure' (one of: ${all[*]})" >&2; exit 2 ;;
  esac
  echo "== $figure"
  "$figure"
done
