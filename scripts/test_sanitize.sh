#!/usr/bin/env bash
# The sanitizer job (run by .ci/run after scripts/test.sh):
#  1. AddressSanitizer + UndefinedBehaviorSanitizer (preset sanitize) over the unit tests of the
#     parsers, drivers and estimator (the areas in ASAN_AREAS: every file format, the V4L2/GPIO/
#     serial drivers through their emulated devices, the front end, RANSAC, the Ceres window, VO,
#     the sun fusion and the pipeline on real KITTI frames);
#  2. ThreadSanitizer (preset tsan) over the rover's threads: the SPSC rings, the frame pool, the
#     MAVLink link and the whole-program tests of sunvo_rover on emulated devices (capture,
#     estimator, sun and telemetry threads);
#  3. the short fuzz run: every libFuzzer harness of tests/fuzz for 10 s (scripts/fuzz.sh; the long
#     run and its results: docs/hardening.md).
# The areas left out start other programs through the shell (their tests exercise the same
# libraries) or render with POV-Ray (minutes per test under a sanitizer).
#
#   scripts/test_sanitize.sh [--asan-only | --tsan-only | --fuzz-only]
#
# Exit status: non-zero when a build fails or a sanitizer reports an error (the sanitizers abort
# the test on the first report: -fno-sanitize-recover=all, halt_on_error=1).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
run_asan=1
run_tsan=1
run_fuzz=1
case "${1:-}" in
  --asan-only) run_tsan=0; run_fuzz=0 ;;
  --tsan-only) run_asan=0; run_fuzz=0 ;;
  --fuzz-only) run_asan=0; run_tsan=0 ;;
  "") ;;
  *) echo "usage: $0 [--asan-only | --tsan-only | --fuzz-only]" >&2; exit 2 ;;
esac
bash scripts/setup.sh --sanitize

ASAN_AREAS="core files kitti dataset geodesy metrics sun sunfusion mavlink serial sysio v4l2 gpio
emulated_devices frontend motion backend vo selfcal pipeline track_stats"
TSAN_TESTS="firmware_spsc_queue_test firmware_frame_pool_test firmware_deadline_test
firmware_mavlink_link_test firmware_rover_devices_test"

stamp() { date +%s; }

# test_targets BUILD_DIR AREA...: the test executables of those areas (<area>_<unit>_test).
test_targets() {
  local dir="$1"
  shift
  local regex
  regex="^($(tr ' ' '|' <<<"$*"))_[a-z0-9_]+_test:"
  ninja -C "${dir}" -t targets all | grep -E "${regex}" | cut -d: -f1 | sort -u
}

if [ "${run_asan}" -eq 1 ]; then
  t0=$(stamp)
  cmake --preset sanitize >/dev/null
  # shellcheck disable=SC2086
  mapfile -t targets < <(test_targets build/sanitize ${ASAN_AREAS})
  cmake --build build/sanitize -j "${jobs}" --target "${targets[@]}"
  t1=$(stamp)
  labels="^($(tr -s ' \n' '|' <<<"${ASAN_AREAS}" | sed 's/|$//'))$"
  ASAN_OPTIONS=detect_leaks=1:halt_on_error=1 UBSAN_OPTIONS=print_stacktrace=1:halt_on_error=1 \
    ctest --test-dir build/sanitize -j "${jobs}" -L "${labels}" --output-on-failure \
    --timeout 600
  echo "test_sanitize: ASan+UBSan ${#targets[@]} test programs: build $((t1 - t0)) s, run $(($(stamp) - t1)) s"
fi

if [ "${run_tsan}" -eq 1 ]; then
  t0=$(stamp)
  cmake --preset tsan >/dev/null
  # shellcheck disable=SC2086
  cmake --build build/tsan -j "${jobs}" --target ${TSAN_TESTS}
  t1=$(stamp)
  export TSAN_OPTIONS="halt_on_error=1:second_deadlock_stack=1:exitcode=66:suppressions=${PWD}/tests/tsan_suppressions.txt"
  # The lock-free rings, the frame pool, the deadline counters and the serial link's threads.
  ctest --test-dir build/tsan -j 1 --output-on-failure --timeout 600 \
    -R '^firmware\.(SpscQueue|FramePool|EventCount|SolverBudget|MavlinkLink)\.'
  # The whole program on emulated devices (capture, estimator, sun, telemetry threads). Under TSan
  # the front end runs ~100x slower (0.63 s per frame), so these tests' real-time expectations
  # (poses per second) fail by design; what counts here is that TSan reports no race: its exit
  # code 66 (or a report in the log) fails the job, a test assertion (exit 1) does not.
  log="build/tsan/rover_devices_tsan.log"
  set +e
  build/tsan/tests/firmware/firmware_rover_devices_test >"${log}" 2>&1
  code=$?
  set -e
  if [ "${code}" -ne 0 ] && [ "${code}" -ne 1 ] || grep -q "WARNING: ThreadSanitizer" "${log}"; then
    grep -A30 "WARNING: ThreadSanitizer" "${log}" | head -60
    echo "test_sanitize: TSan reported a race in the rover's threads (exit ${code}; ${log})"
    exit 1
  fi
  echo "test_sanitize: rover whole-program tests under TSan: no race reported (test exit ${code})"
  echo "test_sanitize: TSan rover threads: build $((t1 - t0)) s, run $(($(stamp) - t1)) s"
fi

if [ "${run_fuzz}" -eq 1 ]; then
  t0=$(stamp)
  bash scripts/fuzz.sh 10
  echo "test_sanitize: fuzz short run (build and 10 s per harness) $(($(stamp) - t0)) s"
fi
