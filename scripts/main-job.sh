#!/usr/bin/env bash
# The main job on the scenes that ship in maps/: install, build, simulate the lab,
# register its scans from odometry and build its ML map, print what it holds, detect its planes.
# Usage: scripts/main-job.sh [SCENE.json] [OUT_DIR]
set -euo pipefail
cd "$(dirname "$0")/.."
scene=${1:-maps/lab.json}
out=${2:-out/$(basename "$scene" .json)}
bash scripts/install-deps.sh
bash scripts/build.sh
mlmap=build/mlmap
"$mlmap" simulate "$scene" -o "$out"
# From the drifting odometry, registered by ICP; the shipped scenes simulate 1 cm range
# noise (XYZ files carry no per-point variance).
"$mlmap" build -o "$out/map.mlmap" --register --poses "$out/poses_odom.txt" --cell-size 0.05 \
  --range-sigma 0.01 "$out"/scan_*.xyz
"$mlmap" info "$out/map.mlmap"
"$mlmap" planes "$out/map.mlmap" --json "$out/planes.json" -o "$out/labelled.mlmap"
