#!/usr/bin/env bash
# Benchmark of the whole onboard program (not a unit test; about 9 minutes per run):
# the rendered 1242x375 CI drive (100 frames, 10 Hz) played ping-pong to FRAMES frames through
# sunvo_rover into a pseudo-terminal read by sunvo_pose_reader. Reports trigger -> serial
# p50/p95/p99/max, deadline misses, heap allocations per frame per thread after warm-up and RSS
# (from the program's summary), and the reader's view of the stream.
#   bash scripts/rover_bench.sh [--frames N] [--load]
#   --load  also runs a competing busy loop (one process, like `stress -c 1`) for the whole run.
# Output: out/rover_bench/ (reader.json, rover.log with the summary, final_latency.csv, trace).
set -euo pipefail
cd "$(dirname "$0")/.."
frames=5000
load=0
while [[ $# -gt 0 ]]; do
  case "$1" in
    --frames) frames=$2; shift 2 ;;
    --load) load=1; shift ;;
    *) echo "usage: $0 [--frames N] [--load]" >&2; exit 2 ;;
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
set +e
"$bin/bin/sunvo_pose_reader" --drive "$drive" --frames "$frames" \
  --timeout-s "$timeout_s" --json "$out/reader.json" --child-log "$out/rover.log" \
  --latency-csv "$out/final_latency.csv" \
  -- "$bin/bin/sunvo_rover" --config config/rover_replay.yaml \
  --set "source.kitti.drive_dir=$drive" --set "sun.csv=$drive/gt/sun_cam0.csv" \
  --set source.kitti.end=pingpong --set "source.kitti.total_frames=$frames" \
  --set "serial.device={pty}" --set "profiling.output_dir=$out" > "$out/reader.txt" 2>&1
status=$?
set -e
echo "machine load after the run: $(cut -d' ' -f1-3 /proc/loadavg)"
sed -n '/sunvo_rover: stopped/,$p' "$out/rover.log"
cat "$out/reader.json"
exit $status
