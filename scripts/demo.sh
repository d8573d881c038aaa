#!/usr/bin/env bash
# The main job on its built-in default: installs what is missing, builds, and runs the paper's
# experiment (pure VO against VO + sun, Table 1 per route, top-view plots) on the real KITTI data
# in ../shared/data. Results go to out/experiment/.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/setup.sh
jobs=$(nproc)
cmake --preset release >/dev/null
cmake --build --preset release -j "$jobs" --target sunvo_experiment_cli
./build/release/hil/experiment/sunvo_experiment --out out/experiment "$@"
