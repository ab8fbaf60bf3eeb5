#!/usr/bin/env bash
# The main job on the scenes that ship in maps/: the paper's corridor and lab (Fig. 11),
# mapped apart from drifting odometry, registered, merged into one map, planes detected,
# exported for octovis and the web dashboard, and a summary printed.
# Usage: scripts/main-job.sh [OUT_DIR]   (default out/building)
set -euo pipefail
cd "$(dirname "$0")/.."
out=${1:-out/building}
bash scripts/install-deps.sh
bash scripts/build.sh
bash scripts/web-build.sh
mlmap=build/mlmap
mkdir -p "$out"
declare -A seconds
step() {  # step NAME command...: runs it and keeps its wall time for the summary
  local name=$1 start=$SECONDS
  shift
  echo "== $name"
  "$@"
  seconds[$name]=$((SECONDS - start))
}

for room in corridor lab; do
  step "simulate $room" "$mlmap" simulate "maps/building_$room.json" -o "$out/$room"
  # Each room in its own frame, from its odometry, registered by ICP; the scenes simulate
  # 1 cm range noise (XYZ files carry no per-point variance).
  step "build $room" "$mlmap" build -o "$out/$room.mlmap" --register --poses "$out/$room/poses_odom.txt" \
    --cell-size 0.05 --range-sigma 0.01 "$out/$room"/scan_*.xyz
done
# The lab's placement from a floor plan is only a guess: ICP between the maps refines it.
step "merge" "$mlmap" merge "$out/corridor.mlmap" "$out/lab.mlmap" --register --initial maps/building_lab_guess.txt \
  --write-transform "$out/lab_in_corridor.txt" -o "$out/building.mlmap"
step "planes" "$mlmap" planes "$out/building.mlmap" --json "$out/planes.json" -o "$out/labelled.mlmap"
step "export" "$mlmap" export "$out/labelled.mlmap" --octovis "$out/building.ot" --dashboard "$out/dashboard"

echo
echo "== summary"
"$mlmap" info "$out/labelled.mlmap"
printf '  %-18s %6s\n' step seconds
for name in "simulate corridor" "build corridor" "simulate lab" "build lab" merge planes export; do
  printf '  %-18s %6s\n' "$name" "${seconds[$name]}"
done
echo "  octovis:   octovis $out/building.ot"
echo "  dashboard: open $out/dashboard/index.html"
