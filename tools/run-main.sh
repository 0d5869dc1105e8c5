#!/usr/bin/env bash
# The main job on the built-in catalogue: installs and builds what it needs, then
# simulates the thesis's worked example (a gun in the right abdomen) into out/gun.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
./build/portalsim simulate none none none gun --rule gun --out out/gun --timing
