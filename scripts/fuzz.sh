#!/usr/bin/env bash
# Builds the libFuzzer targets (fuzz/) with clang in build-fuzz/ and runs each for
# SECONDS_PER_TARGET (default 60), one after the other, then prints per target: CPU
# seconds, executions, coverage (libFuzzer's final cov/ft) and crashes found.
#   scripts/fuzz.sh [SECONDS_PER_TARGET] [TARGET...]   run (all targets by default)
#   scripts/fuzz.sh --seeds                            rewrite fuzz/corpus/ from the writers
# Seeds come from fuzz/corpus/<target>/; what a run adds goes to build-fuzz/corpus/,
# crashing inputs to build-fuzz/artifacts/<target>/. Exit status 1 when anything crashed.
set -euo pipefail
cd "$(dirname "$0")/.."

if ! command -v clang++ > /dev/null || ! ls /usr/lib/llvm-*/lib/clang/*/lib/linux/libclang_rt.fuzzer-x86_64.a > /dev/null 2>&1; then
  sudo=""; [ "$(id -u)" -eq 0 ] || sudo=sudo
  $sudo apt-get update -qq
  $sudo apt-get install -y -qq clang libclang-rt-14-dev > /dev/null
fi

mkdir -p build-fuzz
CC=clang CXX=clang++ cmake -S . -B build-fuzz -DCMAKE_BUILD_TYPE=RelWithDebInfo -DMLMAP_FUZZ=ON \
  -DMLMAP_TESTS=OFF -DMLMAP_OPENMP=OFF > build-fuzz/build.log 2>&1 || { cat build-fuzz/build.log; exit 1; }

if [ "${1:-}" = "--seeds" ]; then
  cmake --build build-fuzz -j2 --target mlmap_fuzz_seeds >> build-fuzz/build.log 2>&1 || { tail -50 build-fuzz/build.log; exit 1; }
  rm -rf fuzz/corpus
  build-fuzz/fuzz/mlmap_fuzz_seeds fuzz/corpus
  find fuzz/corpus -type f | sort
  exit 0
fi

seconds="${1:-60}"
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=($(ls fuzz/corpus))
fi
cmake --build build-fuzz -j2 --target mlmap_fuzz >> build-fuzz/build.log 2>&1 || { tail -50 build-fuzz/build.log; exit 1; }

results=()
crashed=0
for target in "${targets[@]}"; do
  corpus="build-fuzz/corpus/$target"
  artifacts="build-fuzz/artifacts/$target"
  mkdir -p "$corpus" "$artifacts"
  cp -n fuzz/corpus/"$target"/* "$corpus"/
  before=$(ls "$artifacts" | wc -l)
  log="build-fuzz/fuzz_$target.log"
  TIMEFORMAT='%U %S'
  # -timeout: one input running 10 s is a hang; -rss_limit_mb / -malloc_limit_mb: an OOM.
  cpu=$( { time build-fuzz/fuzz/fuzz_"$target" "$corpus" -max_total_time="$seconds" -timeout=10 \
      -rss_limit_mb=2048 -malloc_limit_mb=1024 -print_final_stats=1 \
      -artifact_prefix="$artifacts/" > "$log" 2>&1 || true; } 2>&1 | awk '{printf "%.1f", $1 + $2}')
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  coverage=$(grep -Eo 'cov: [0-9]+ ft: [0-9]+' "$log" | tail -1)
  found=$(( $(ls "$artifacts" | wc -l) - before ))
  [ "$found" -eq 0 ] || crashed=1
  results+=("$(printf '%-12s %8s %12s %-22s %s' "$target" "$cpu" "${execs:-?}" "${coverage:-?}" "$found")")
  echo "${results[-1]}"
done

echo
printf '%-12s %8s %12s %-22s %s\n' target "CPU s" executions coverage crashes
printf '%s\n' "${results[@]}"
[ "$crashed" -eq 0 ] || { echo "crashing inputs: build-fuzz/artifacts/ (logs: build-fuzz/fuzz_*.log)"; exit 1; }
