#!/usr/bin/env bash
# The viewer test's map, made by the built CLI as a user would: the lab scanned coarsely
# (tests/fixtures/lab-coarse.scene.json), built at 0.1 m cells from its true poses, planes
# detected, then `mlmap export --dashboard` into test-output/lab-export/ (index.html,
# planes.json/.js, blocks.bin/.js, voxels.bin/.js). Usage: lab-export.sh [OUT_DIR]; MLMAP=path overrides
# the CLI (default: build/mlmap beside web/). About 10 s.
set -euo pipefail
web="$(cd "$(dirname "$0")/.." && pwd)"
mlmap="${MLMAP:-$web/../build/mlmap}"
out="${1:-$web/test-output/lab-export}"
if [ ! -x "$mlmap" ]; then
  echo "lab-export.sh: $mlmap is missing: build the CLI first (bash scripts/build.sh), or set MLMAP" >&2
  exit 1
fi
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
"$mlmap" --quiet simulate "$web/tests/fixtures/lab-coarse.scene.json" -o "$work/sim" > /dev/null
"$mlmap" --quiet build --poses "$work/sim/poses_true.txt" --cell-size 0.1 --range-sigma 0.01 \
  -o "$work/lab.mlmap" "$work"/sim/scan_*.xyz > /dev/null
"$mlmap" --quiet planes "$work/lab.mlmap" -o "$work/lab.mlmap" > /dev/null
"$mlmap" --quiet export "$work/lab.mlmap" --dashboard "$out" --dashboard-voxels --dashboard-page "$web/dist/index.html"
