#!/usr/bin/env bash
# Builds the libFuzzer harnesses (preset fuzz: clang-14, ASan + UBSan) and runs each one on its
# seed corpus for SECONDS seconds (default 10: the short run), or for RUNS executions with --runs.
#   bash scripts/fuzz.sh                 # every harness, 10 s each
#   bash scripts/fuzz.sh 600             # the long run (docs/hardening.md)
#   bash scripts/fuzz.sh --runs 1000000 poses mavlink
# The corpus grows in build/fuzz/corpus/<parser> (the seeds in tests/fuzz/corpus are only read);
# a crash leaves build/fuzz/artifacts/<parser>/crash-* and a non-zero exit.
set -euo pipefail
cd "$(dirname "$0")/.."
limit=(-max_total_time=10)
if [[ "${1:-}" == "--runs" ]]; then
  limit=(-runs="$2")
  shift 2
elif [[ "${1:-}" =~ ^[0-9]+$ ]]; then
  limit=(-max_total_time="$1")
  shift
fi
all=(kitti_calibration kitti_timestamps oxts poses tracks sun_csv mavlink rover_yaml stereo_calibration
  sun_cnn_options)
harnesses=("$@")
[[ ${#harnesses[@]} -eq 0 ]] && harnesses=("${all[@]}")
cmake --preset fuzz >/dev/null
targets=()
for h in "${harnesses[@]}"; do targets+=("fuzz_$h"); done
cmake --build build/fuzz -j "$(nproc)" --target "${targets[@]}"
# yaml-cpp and OpenCV are not instrumented; their leaks of static data are not sunvo's.
export ASAN_OPTIONS="${ASAN_OPTIONS:-detect_leaks=1}"
export UBSAN_OPTIONS="${UBSAN_OPTIONS:-print_stacktrace=1:halt_on_error=1}"
status=0
for h in "${harnesses[@]}"; do
  corpus="build/fuzz/corpus/$h"
  artifacts="build/fuzz/artifacts/$h/"
  mkdir -p "$corpus" "$artifacts"
  log="build/fuzz/$h.log"
  start=$(date +%s)
  if build/fuzz/bin/fuzz_"$h" "${limit[@]}" -max_len=4096 -print_final_stats=1 \
      -artifact_prefix="$artifacts" "$corpus" "tests/fuzz/corpus/$h" >"$log" 2>&1; then
    result=ok
  else
    result="CRASH (see $log and $artifacts)"
    status=1
  fi
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  printf '%-18s %10s executions in %4d s: %s\n' "$h" "${execs:-?}" "$(( $(date +%s) - start ))" \
    "$result"
done
exit "$status"
