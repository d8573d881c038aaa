#!/usr/bin/env bash
# Pure VO with and without the online stereo self-calibration, side by side (issue 15), on real
# feature-track folders (sunvo_experiment) and on rendered or recorded image drives (sunvo_replay).
#
#   bash scripts/selfcal_compare.sh [--out DIR] [--tracks ROUTE]... [--drive DRIVE]...
#
# ROUTE: what sunvo_experiment --routes takes (0020, a KITTI odometry id, a track folder).
# DRIVE: what sunvo_replay --drive takes (a sunvo_render output drive, a KITTI raw drive).
# Without any --tracks/--drive: 0020 and, when rendered, the CI drive and its rig-error twin
# (config/scenarios/ci_short.yaml, ci_short_rig_error.yaml rendered under build/release/render_cache
# or /work/renders/rig). Needs the release build (cmake --preset release && cmake --build ...).
# Writes DIR/compare.md (one Table-1 row pair per input) and keeps every run's own tables and
# top-view plots under DIR/<input>/{off,on}/.
set -euo pipefail
cd "$(dirname "$0")/.."
out=selfcal_compare
tracks=()
drives=()
while [[ $# -gt 0 ]]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --tracks) tracks+=("$2"); shift 2 ;;
    --drive) drives+=("$2"); shift 2 ;;
    -h|--help) sed -n '2,13p' "$0"; exit 0 ;;
    *) echo "selfcal_compare.sh: unknown argument '$1' (see --help)" >&2; exit 2 ;;
  esac
done
bin=build/release/bin
for p in sunvo_experiment sunvo_replay; do
  [[ -x "$bin/$p" ]] || { echo "selfcal_compare.sh: $bin/$p missing: build the release preset" >&2; exit 1; }
done
if [[ ${#tracks[@]} -eq 0 && ${#drives[@]} -eq 0 ]]; then
  tracks=(0020)
  for d in build/release/render_cache/ci_short/*/*_sync /work/renders/rig/*/*_sync; do
    [[ -d "$d" ]] && drives+=("$d")
  done
fi
mkdir -p "$out"
rows="$out/rows.tsv"
: > "$rows"
# One input, both ways: its metrics JSON path and the self-calibration's final line per side.
for r in "${tracks[@]}"; do
  id=$(basename "$r")
  for side in off on; do
    flag=(); [[ $side == on ]] && flag=(--self-calib)
    mkdir -p "$out/tracks_$id"
    "$bin/sunvo_experiment" --routes "$r" --out "$out/tracks_$id/$side" "${flag[@]}" \
      > "$out/tracks_$id/$side.log" 2>&1
    json=$(find "$out/tracks_$id/$side" -maxdepth 1 -name "route_*_metrics.json" | head -1)
    printf 'tracks %s\t%s\t%s\t%s\n' "$id" "$side" "$json" \
      "$(grep -m1 -o 'self-calibration[^|]*' "$out/tracks_$id/$side.log" || true)" >> "$rows"
  done
done
for d in "${drives[@]}"; do
  id=$(basename "$(dirname "$(dirname "$d")")")_$(basename "$d")
  for side in off on; do
    flag=(); [[ $side == on ]] && flag=(--self-calib)
    mkdir -p "$out/drive_$id"
    "$bin/sunvo_replay" --drive "$d" --no-error-models --out "$out/drive_$id/$side" "${flag[@]}" \
      > "$out/drive_$id/$side.log" 2>&1
    printf 'drive %s\t%s\t%s\t%s\n' "$id" "$side" "$out/drive_$id/$side/replay_metrics.json" \
      "$(grep -m1 -o 'self-calibration:.*' "$out/drive_$id/$side.log" || true)" >> "$rows"
  done
done
python3 - "$rows" > "$out/compare.md" <<'EOF'
import json, sys
rows = [l.rstrip('\n').split('\t') for l in open(sys.argv[1]) if l.strip()]
by = {}
for name, side, path, note in rows:
    t = json.load(open(path))['estimates'][0]['table1']  # run 0 is pure VO in both programs
    by.setdefault(name, {})[side] = (t, note)
print('| input | final drift off → on [m] (%) | trans. ARMSE off → on [m] | rot. ARMSE off → on [1e-3] | self-calibration at the end |')
print('|---|---|---|---|---|')
for name, s in by.items():
    (a, _), (b, note) = s['off'], s['on']
    ch = lambda x, y: 100.0 * (y - x) / x if x else 0.0
    print('| %s | %.3f → %.3f (%.2f → %.2f %%, %+.0f %%) | %.3f → %.3f | %.2f → %.2f | %s |' % (
        name, a['final_drift_m'], b['final_drift_m'], a['final_drift_pct'], b['final_drift_pct'],
        ch(a['final_drift_m'], b['final_drift_m']), a['trans_armse_m'], b['trans_armse_m'],
        1e3 * a['rot_armse_rad'], 1e3 * b['rot_armse_rad'], note.strip() or '-'))
EOF
cat "$out/compare.md"
echo "selfcal_compare.sh: wrote $out/compare.md; per-run tables and top-view plots under $out/"
