#!/usr/bin/env bash
# ctest: install mlmap into a scratch prefix, build examples/ against it with
# find_package(mlmap) as another project would, and run it on a simulated room.
#   install_consumer.sh BUILD_DIR SOURCE_DIR
set -euo pipefail
build=$1
source=$2
work=$build/install-test
rm -rf "$work"
mkdir -p "$work"
step() {  # step NAME COMMAND...: the command's output in a log, shown when it fails
  local name=$1
  shift
  if ! "$@" > "$work/$name.log" 2>&1; then
    echo "install_consumer: $name failed:"
    cat "$work/$name.log"
    exit 1
  fi
}
step install cmake --install "$build" --prefix "$work/prefix"
step configure cmake -S "$source/examples" -B "$work/example" -DCMAKE_PREFIX_PATH="$work/prefix"
step build cmake --build "$work/example"
cat > "$work/room.json" <<'SCENE'
{"name": "room", "poses": [{"x": 2.0, "y": 1.5}, {"x": 4.0, "y": 2.5, "yaw_deg": 180}],
 "surfaces": [
  {"type": "rectangle", "name": "floor", "class": "floor", "min": [0, 0, 0], "max": [6, 4, 0]},
  {"type": "rectangle", "name": "ceiling", "class": "ceiling", "min": [0, 0, 3], "max": [6, 4, 3]},
  {"type": "rectangle", "name": "west", "class": "wall", "min": [0, 0, 0], "max": [0, 4, 3]},
  {"type": "rectangle", "name": "east", "class": "wall", "min": [6, 0, 0], "max": [6, 4, 3]},
  {"type": "rectangle", "name": "south", "class": "wall", "min": [0, 0, 0], "max": [6, 0, 3]},
  {"type": "rectangle", "name": "north", "class": "wall", "min": [0, 4, 0], "max": [6, 4, 3]}]}
SCENE
step simulate "$work/prefix/bin/mlmap" -q simulate "$work/room.json" -o "$work/room"
step report "$work/example/plane_report" 0.1 "$work/room/all_world.xyz"
cat "$work/report.log"
# The room's six faces, each one patch of its class where it is (n·x + d = 0, d
# within 5 cm): floor d = 0, ceiling −3, walls 0, −4 or −6.
awk '
  { d = $(NF - 1); count[$2]++; ok = 0
    if ($2 == "floor") ok = d > -0.05 && d < 0.05
    if ($2 == "ceiling") ok = d > -3.05 && d < -2.95
    if ($2 == "wall") ok = (d > -0.05 && d < 0.05) || (d > -4.05 && d < -3.95) || (d > -6.05 && d < -5.95)
    if (!ok) { print "install_consumer: misplaced: " $0; bad = 1 } }
  END { if (NR != 6 || count["floor"] != 1 || count["ceiling"] != 1 || count["wall"] != 4) {
          print "install_consumer: expected a floor, a ceiling and four walls"; bad = 1 }
        exit bad }' "$work/report.log"
echo "install_consumer: installed, found by find_package, built and run"
