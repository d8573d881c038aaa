#!/usr/bin/env bash
# The main job on its built-in default. Installs what is missing, builds, then:
#  1. the paper's experiment on the real KITTI data in ../shared/data: pure VO against VO + sun,
#     Table 1 per route, top-view plots -> out/experiment/
#  2. renders the 100-frame CI drive with POV-Ray (cached in build/release/render_cache; about
#     5 minutes on 2 cores the first time) and replays it through the whole chain -> out/replay/
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
jobs=$(nproc)
cmake --preset release >/dev/null
cmake --build --preset release -j "$jobs" \
  --target sunvo_experiment_cli sunvo_render_tool sunvo_replay_cli
bin=build/release/bin

"$bin/sunvo_experiment" --out out/experiment

cache=build/release/render_cache/ci_short
drive=$(ls -d "$cache"/*/*_drive_*_sync 2>/dev/null | head -n 1 || true)
if [ -z "$drive" ] || [ ! -f "$drive/gt/poses_cam0_enu.txt" ] ||
   [ "$(ls "$drive/image_00/data" | wc -l)" -ne 100 ]; then
  rm -rf "$cache"
  "$bin/sunvo_render" --scenario config/scenarios/ci_short.yaml --out "$cache" -j "$jobs"
  drive=$(ls -d "$cache"/*/*_drive_*_sync | head -n 1)
fi
"$bin/sunvo_replay" --drive "$drive" --out out/replay
