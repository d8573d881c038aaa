#!/usr/bin/env bash
# Sun-CNN: renders the training, validation and test drives (skipped when already rendered),
# writes the manifest and the SHA-256 of the training data, trains the colour and the grey
# model with PyTorch (CPU) and exports config/sun_cnn{,_gray}.onnx + .json + parity references.
#
#   bash scripts/train_sun_cnn.sh                 # render what is missing, then train
#   bash scripts/train_sun_cnn.sh --render-only   # only render (and write the manifest)
#   bash scripts/train_sun_cnn.sh --real DIR:CSV[:SPLIT] ...   # real labelled images as well
#   bash scripts/train_sun_cnn.sh --no-render --real DIR:CSV:train ...  # no rendering
#
# --real DIR:CSV[:SPLIT] (repeatable) adds a real KITTI odometry folder (image_0/1 gray, image_2/3
# colour) or KITTI raw drive folder (image_00..03/data) with its per-frame sun file (CSV
# frame,sx,sy,sz, the sun in camera 0, e.g. ../shared/data/kitti_odometry/00_sun_cam.csv) to the
# manifest as scenario real_<folder name>; SPLIT is train, val or test (default test: held out,
# reported only). --no-render renders nothing: the manifest lists the renders already complete
# under $SUNVO_RENDERS (none is fine) and the --real folders; with --render-only as well, the
# script only writes the manifest. See estimator/suncnn/training/sun_cnn_manifest.py.
#
# Needs: the sunvo_render tool (built here if missing), povray, and python3-torch
# (bash scripts/setup.sh --train). Renders go to $SUNVO_RENDERS (default /work/renders), one
# folder per scenario (config/scenarios/): train_* (training; styled, training looks), val_*
# (validation: held-out places, times and looks; the sigma scale and validity threshold are
# chosen on it) and test_* (held-out looks, reported only).
# config/scenarios/candidate_*.yaml (24 extreme-sun drives) are neither rendered nor trained: they
# made a one-member model worse on the validation drives (docs/sun_cnn.md).
# The manifest is $SUNVO_RENDERS/sun_cnn_manifest.csv.
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/.." && pwd)"
BUILD="${SUNVO_BUILD:-$ROOT/build/release}"
RENDERS="${SUNVO_RENDERS:-/work/renders}"
JOBS="${JOBS:-2}"
PY=/usr/bin/python3  # Debian's interpreter, the one python3-torch is installed for
MODE=all
RENDER=1
REAL=()
while [ $# -gt 0 ]; do
  case "$1" in
    --render-only) MODE=--render-only; shift ;;
    --no-render) RENDER=0; shift ;;
    --real)
      [ $# -ge 2 ] || { echo "train_sun_cnn: --real needs DIR:CSV[:SPLIT]" >&2; exit 2; }
      REAL+=(--real "$2"); shift 2 ;;
    *) echo "train_sun_cnn: unknown argument $1" >&2; exit 2 ;;
  esac
done

if [ "$RENDER" = 1 ] && [ ! -x "$BUILD/bin/sunvo_render" ]; then
  (cd "$ROOT" && cmake --preset release >/dev/null && cmake --build "$BUILD" --target sunvo_render_tool)
fi

mkdir -p "$RENDERS"
for yaml in "$ROOT"/config/scenarios/train_*.yaml "$ROOT"/config/scenarios/val_*.yaml \
  "$ROOT"/config/scenarios/test_*.yaml; do
  name="$(basename "$yaml" .yaml)"
  out="$RENDERS/$name"
  # RENDERED holds the SHA-256 of the scenario it was rendered from: a changed scenario renders again.
  want="$(sha256sum "$yaml" | cut -d' ' -f1)"
  if [ -f "$out/RENDERED" ] && [ "$(cat "$out/RENDERED")" = "$want" ]; then continue; fi
  [ "$RENDER" = 1 ] || continue  # --no-render: leave what is (not) rendered as it is
  rm -rf "$out"
  echo "train_sun_cnn: rendering $name"
  nice -n 10 "$BUILD/bin/sunvo_render" --scenario "$yaml" --out "$out" -j "$JOBS"
  rm -rf "$out"/*/*_sync/pov   # POV-Ray sources and sky maps: not needed for training
  echo "$want" >"$out/RENDERED"
done

"$PY" "$ROOT/estimator/suncnn/training/sun_cnn_manifest.py" --renders "$RENDERS" \
  --out "$RENDERS/sun_cnn_manifest.csv" "${REAL[@]}"
[ "$MODE" = "--render-only" ] && exit 0

"$PY" -c "import torch" 2>/dev/null || {
  echo "train_sun_cnn: python3-torch missing: bash scripts/setup.sh --train" >&2
  exit 1
}
# The colour and the grey model train side by side, one thread each (a model is reproducible
# for a given thread count); their logs go to $RENDERS/train_<name>.log.
pids=()
for model in colour gray; do
  # The shipped models' recipes: colour 80 epochs (chosen on the validation drives, 2026-11-27),
  # grey 40 (not retrained at 80 yet).
  if [ "$model" = colour ]; then name=sun_cnn channels=3 epochs=80; else name=sun_cnn_gray channels=1 epochs=40; fi
  (cd "$ROOT/estimator/suncnn/training" && nice -n 10 "$PY" sun_cnn_train.py --threads 1 --epochs "$epochs" \
    --manifest "$RENDERS/sun_cnn_manifest.csv" --out-dir "$ROOT/config" --name "$name" \
    --channels "$channels" --reference "$ROOT/tests/suncnn/data/${name}_reference.txt" \
    >"$RENDERS/train_$name.log" 2>&1) &
  pids+=($!)
done
status=0
for p in "${pids[@]}"; do wait "$p" || status=1; done
tail -n 25 "$RENDERS"/train_sun_cnn*.log
[ "$status" = 0 ] || exit "$status"
# The feature term (its prior is fitted on the manifest's training rows) and the numbers that go
# with it, chosen on the validation rows as in training (docs/sun_cnn_calibration.md).
for name in sun_cnn sun_cnn_gray; do
  (cd "$ROOT/estimator/suncnn/training" && "$PY" sun_cnn_calibrate.py \
    --manifest "$RENDERS/sun_cnn_manifest.csv" --model "$ROOT/config/$name.onnx") || exit 1
done
