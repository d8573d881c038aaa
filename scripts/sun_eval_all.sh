#!/usr/bin/env bash
# One command over every held-out image set: runs sunvo_sun_eval once, with one --images per
# set, prints its tables (one row per set and estimator; one per set, Lalonde estimator and cue)
# and leaves in OUT: sun_eval.{md,json,csv}, hist/ (error histograms), frames/ (per frame) and
# debug/ (Lalonde panels).
#
#   bash scripts/sun_eval_all.sh [--out DIR] [SET ...] [-- sunvo_sun_eval options]
#
# SET: a set folder (a sunvo render or its drive folder, a KITTI raw drive, a KITTI odometry
# folder with image_0/1 or image_2/3) or DIR:CSV with the true sun in CSV (frame,sx,sy,sz in
# camera 0). Without a SET: every held-out set at hand, i.e. the rendered folders under
# $SUNVO_RENDERS (default /work/renders) named heldout_*, val_* or test_* that hold a drive with
# gt/sun_cam0.csv, and the 11 real KITTI 00 frames of $SUNVO_DATA_DIR (default ../shared/data
# next to the checkout). The training renders (train_*) are never evaluated by default.
#
# Options after "--" go to sunvo_sun_eval as they are, e.g. -- --estimators lalonde,sun_cnn
# --frames 20 --model config/sun_cnn_gray.onnx. OUT defaults to out/sun_eval_all. Exit code: the
# tool's (0 done, 1 an input or estimator failed, 2 bad arguments).
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${SUNVO_BUILD:-$ROOT/build/release}"
RENDERS="${SUNVO_RENDERS:-/work/renders}"
DATA="${SUNVO_DATA_DIR:-$(cd "$ROOT/.." && pwd)/shared/data}"
OUT="$ROOT/out/sun_eval_all"
EXE="$BUILD/bin/sunvo_sun_eval"

sets=()
extra=()
while [ $# -gt 0 ]; do
  case "$1" in
    --out) OUT="$2"; shift 2 ;;
    --) shift; extra=("$@"); break ;;
    -h|--help) sed -n '2,19p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    -*) echo "sun_eval_all: unknown option $1 (sunvo_sun_eval's options go after --)" >&2; exit 2 ;;
    *) sets+=("$1"); shift ;;
  esac
done

if [ ${#sets[@]} -eq 0 ]; then
  shopt -s nullglob
  for d in "$RENDERS"/heldout_* "$RENDERS"/val_* "$RENDERS"/test_*; do
    drives=("$d"/*/*_sync/gt/sun_cam0.csv)
    [ ${#drives[@]} -gt 0 ] && sets+=("$d")
  done
  shopt -u nullglob
  real="$DATA/kitti_odometry/00_first_frames"
  [ -d "$real" ] && sets+=("$real")
fi
if [ ${#sets[@]} -eq 0 ]; then
  echo "sun_eval_all: no set given and none found under $RENDERS or $DATA" >&2
  exit 2
fi

if [ ! -x "$EXE" ]; then
  (cd "$ROOT" && cmake --preset release >/dev/null && cmake --build "$BUILD" --target sunvo_sun_eval)
fi

args=()
for s in "${sets[@]}"; do args+=(--images "$s"); done
echo "sun_eval_all: ${#sets[@]} set(s): ${sets[*]}" >&2
exec "$EXE" "${args[@]}" --out "$OUT" "${extra[@]}"
