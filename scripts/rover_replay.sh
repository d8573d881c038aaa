#!/usr/bin/env bash
# Replays the rendered CI drive through the whole onboard program: sunvo_pose_reader opens a
# pseudo-terminal, starts sunvo_rover (config/rover_replay.yaml: file source paced at the
# recorded rate, simulated trigger, threads, MAVLink on the pty), decodes every pose, stops the
# program with SIGTERM and reports accuracy (Table 1 against the renderer's ground truth) and
# latency (trigger -> last byte written, trigger -> byte received).
#   bash scripts/rover_replay.sh            # builds what is missing; renders the drive if needed
# Output: out/rover_replay/ (reader.json, rover.log, final_latency.csv, final_trace.json).
set -euo pipefail
cd "$(dirname "$0")/.."
cmake --preset release >/dev/null
cmake --build --preset release --target sunvo_rover sunvo_pose_reader sunvo_render_tool >/dev/null
bin=build/release
cache=$bin/render_cache/ci_short
drive=$(ls -d "$cache"/*/*_drive_*_sync 2>/dev/null | head -n 1 || true)
if [[ -z "$drive" || ! -f "$drive/gt/poses_cam0_enu.txt" ]]; then
  echo "rendering the CI drive (100 frames, a few minutes) into $cache"
  rm -rf "$cache"
  "$bin/bin/sunvo_render" --scenario config/scenarios/ci_short.yaml --out "$cache" -j "$(nproc)"
  drive=$(ls -d "$cache"/*/*_drive_*_sync | head -n 1)
fi
frames=$(wc -l < "$drive/image_00/timestamps.txt")
out=out/rover_replay
mkdir -p "$out"
"$bin/bin/sunvo_pose_reader" --drive "$drive" --frames "$frames" --timeout-s 120 \
  --json "$out/reader.json" --child-log "$out/rover.log" --latency-csv "$out/final_latency.csv" \
  -- "$bin/bin/sunvo_rover" --config config/rover_replay.yaml \
  --set "source.kitti.drive_dir=$drive" --set "sun.csv=$drive/gt/sun_cam0.csv" \
  --set "serial.device={pty}" --set "profiling.output_dir=$out"
status=$?
sed -n '/sunvo_rover: stopped/,$p' "$out/rover.log"
exit $status
