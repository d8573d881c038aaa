#!/usr/bin/env python3
"""Whether a track folder's subpixel measurements lock to whole pixels (issue 15, docs/selfcal.md).

A subpixel estimator on images that alias (a render with one ray per pixel) draws its estimates
towards whole pixels; on band-limited images the fractional parts are uniform, so 2 % of them lie
within 0.01 px of a whole pixel. For every observation of TRACKS/tracks.csv (frame, landmark, uL,
vL, uR, vR[, vR_measured]) this prints, for the row offset vL - vR (only where the right row was
measured: vR_measured 1 or no such column), the disparity uL - uR and the left coordinates uL and
vL, the share within 0.01 px of a whole pixel and the share of |fractional part| in each 0.05 px
step (0-0.05 px, ..., 0.45-0.5 px; 10 % each when uniform).
Runs on real track folders (kitti_tracks/*) and on the ones `sunvo_replay --write-tracks` writes.
No dependencies beyond Python. Usage: pixel_locking.py TRACKS
"""
import csv
import sys


def main():
    if len(sys.argv) != 2:
        raise SystemExit(__doc__.strip().splitlines()[-1])
    path = sys.argv[1] + "/tracks.csv"
    names = ("vL - vR", "uL - uR", "uL", "vL")
    near = [0] * len(names)
    steps = [[0] * 10 for _ in names]  # |fraction| by 0.05 px
    counts = [0] * len(names)
    with open(path, newline="") as f:
        rows = csv.reader(f)
        header = next(rows, None)
        if header is None or header[:6] != ["frame", "landmark", "uL", "vL", "uR", "vR"]:
            raise SystemExit(f"{path}:1: expected the header frame,landmark,uL,vL,uR,vR")
        measured = header.index("vR_measured") if "vR_measured" in header else -1
        for line, row in enumerate(rows, start=2):
            try:
                uL, vL, uR, vR = (float(x) for x in row[2:6])
            except (ValueError, IndexError):
                raise SystemExit(f"{path}:{line}: expected four numbers in uL,vL,uR,vR")
            for i, value in enumerate((vL - vR, uL - uR, uL, vL)):
                if i == 0 and measured >= 0 and row[measured] != "1":
                    continue  # vR is a copy of vL
                counts[i] += 1
                frac = abs(value - round(value))
                near[i] += frac < 0.01
                steps[i][min(int(frac / 0.05), 9)] += 1
    if counts[1] == 0:
        raise SystemExit(f"{path}: no observations")
    print(f"{path}: {counts[1]} observations, {counts[0]} with a measured right row")
    for i, name in enumerate(names):
        n = max(counts[i], 1)
        shares = " ".join(f"{100 * c / n:4.1f}" for c in steps[i])
        print(f"{name:8s} within 0.01 px of a whole pixel {100 * near[i] / n:5.2f} % "
              f"(2 % if uniform); by |fraction| in 0.05 px steps [%]: {shares}")


if __name__ == "__main__":
    main()
