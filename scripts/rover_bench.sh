#!/usr/bin/env bash
# Benchmark of the whole onboard program (not a unit test; about 9 minutes per run):
# the rendered 1242x375 CI drive (100 frames, 10 Hz) played ping-pong to FRAMES frames through
# sunvo_rover into a pseudo-terminal read by sunvo_pose_reader. Reports trigger -> serial
# p50/p95/p99/max, deadline misses, heap allocations per frame per thread after warm-up and RSS
# (from the program's summary), and the reader's view of the stream.
#   bash scripts/rover_bench.sh [--frames N] [--load] [--faults RATE [--seed N]]
#   --load    also runs a competing busy loop (one process, like `stress -c 1`) for the whole run.
#   --faults  the soak: injects missed triggers, bad frames and black frames, each at RATE
#             (source.faults, seeded), loops the drive until FRAMES poses have been read, and
#             checks that the health counters account for every injected fault, that the RSS did
#             not grow after the warm-up and that at most 0.1 % of the poses missed the deadline
#             (exit 1 otherwise).
# Output: out/rover_bench/ (reader.json, rover.log with the summary, final_latency.csv, trace).
set -euo pipefail
cd "$(dirname "$0")/.."
frames=5000
load=0
faults=""
seed=1
while [[ $# -gt 0 ]]; do
  case "$1" in
    --frames) frames=$2; shift 2 ;;
    --load) load=1; shift ;;
    --faults) faults=$2; shift 2 ;;
    --seed) seed=$2; shift 2 ;;
    *) echo "usage: $0 [--frames N] [--load] [--faults RATE [--seed N]]" >&2; exit 2 ;;
  esac
done
cmake --preset release >/dev/null
cmake --build --preset release --target sunvo_rover sunvo_pose_reader >/dev/null
bin=build/release
drive=$(ls -d "$bin"/render_cache/ci_short/*/*_drive_*_sync 2>/dev/null | head -n 1 || true)
if [[ -z "$drive" ]]; then
  echo "no rendered CI drive in $bin/render_cache/ci_short: run scripts/demo.sh (or rover_replay.sh) first" >&2
  exit 1
fi
out=out/rover_bench
rm -rf "$out"
mkdir -p "$out"
load_pid=""
if [[ $load -eq 1 ]]; then
  bash -c 'while :; do :; done' &
  load_pid=$!
  trap '[[ -n "$load_pid" ]] && kill "$load_pid" 2>/dev/null || true' EXIT
  echo "competing load: busy loop pid $load_pid"
fi
echo "machine load before the run: $(cut -d' ' -f1-3 /proc/loadavg) ($(nproc) CPUs)"
timeout_s=$(( frames / 10 + 120 ))
# Without faults the replay ends after FRAMES triggers; with them some triggers give no pose, so
# the drive loops on and the reader stops the program after FRAMES poses.
extra=(--set "source.kitti.total_frames=$frames")
if [[ -n "$faults" ]]; then
  extra=(--set source.kitti.total_frames=0 --set "source.faults.seed=$seed"
         --set "source.faults.missed_trigger_rate=$faults" --set "source.faults.bad_frame_rate=$faults"
         --set "source.faults.dark_frame_rate=$faults")
  timeout_s=$(( frames * 2 / 10 + 120 ))
fi
set +e
"$bin/bin/sunvo_pose_reader" --drive "$drive" --frames "$frames" \
  --timeout-s "$timeout_s" --json "$out/reader.json" --child-log "$out/rover.log" \
  --latency-csv "$out/final_latency.csv" \
  -- "$bin/bin/sunvo_rover" --config config/rover_replay.yaml \
  --set "source.kitti.drive_dir=$drive" --set "sun.csv=$drive/gt/sun_cam0.csv" \
  --set source.kitti.end=pingpong "${extra[@]}" \
  --set "serial.device={pty}" --set "profiling.output_dir=$out" > "$out/reader.txt" 2>&1
status=$?
set -e
echo "machine load after the run: $(cut -d' ' -f1-3 /proc/loadavg)"
sed -n '/sunvo_rover: stopped/,$p' "$out/rover.log"
cat "$out/reader.json"
if [[ -n "$faults" ]]; then
  # The soak's checks, from the program's summary (rover.log) and the reader's view. The reader's
  # own verdict needs every frame of the first pass for its accuracy figures, which injected
  # faults remove, so it is not used here.
  log="$out/rover.log"
  num() { grep -oE "$1" "$log" | head -n 1 | grep -oE '[0-9]+$'; }
  missed_inj=$(num 'missed triggers [0-9]+'); bad_inj=$(num 'bad frames [0-9]+')
  dark_inj=$(num 'dark frames [0-9]+')
  missed=$(num 'missed [0-9]+'); grab_errors=$(num 'grab errors [0-9]+')
  losses=$(num 'tracking: losses [0-9]+'); recoveries=$(num 'recoveries [0-9]+')
  published=$(num 'poses published [0-9]+'); misses=$(num '> [0-9]+ ms\) [0-9]+')
  rss_growth=$(grep -oE 'growth after warm-up -?[0-9]+' "$log" | grep -oE -- '-?[0-9]+$' || true)
  verdict=0
  check() { if eval "$2"; then echo "soak check ok:     $1"; else echo "soak check FAILED: $1"; verdict=1; fi; }
  check "missed triggers counted $missed = injected $missed_inj" "[[ $missed -eq $missed_inj ]]"
  check "grab errors $grab_errors = injected bad frames $bad_inj" "[[ $grab_errors -eq $bad_inj ]]"
  check "tracking losses $losses and recoveries $recoveries >= injected dark frames $dark_inj" \
    "[[ $losses -ge $dark_inj && $recoveries -ge $dark_inj ]]"
  check "deadline misses $misses of $published poses <= 0.1 %" "[[ $(( misses * 1000 )) -le $published ]]"
  jnum() { grep -oE "\"$1\": [a-z0-9.]+" "$out/reader.json" | head -n 1 | awk '{print $2}'; }
  check "poses read $(jnum odometry_received) = $frames, CRC errors $(jnum crc_errors), clean exit $(jnum clean_exit)" \
    "[[ $(jnum odometry_received) -eq $frames && $(jnum crc_errors) -eq 0 && $(jnum clean_exit) == true ]]"
  check "RSS growth after warm-up ${rss_growth:-?} kB = 0" "[[ '${rss_growth:-x}' == 0 ]]"
  exit $verdict
fi
exit $status
