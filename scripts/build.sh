#!/usr/bin/env bash
# Configures and builds mlmap in build/ (Release, OpenMP on). Extra arguments go to CMake.
set -euo pipefail
cd "$(dirname "$0")/.."
source scripts/ccache-env.sh
cmake -S . -B build -DCMAKE_BUILD_TYPE=Release "${MLMAP_LAUNCHER[@]}" "$@" > build.log 2>&1 || { cat build.log; exit 1; }
cmake --build build -j"$(nproc)" >> build.log 2>&1 || { tail -50 build.log; exit 1; }
