#!/usr/bin/env python3
"""A rendered drive's tracks with its injected rig error taken out exactly (issue 15).

An oracle for the self-calibration: what pure VO would do if it knew the right camera's turn. Reads
a track folder written by `sunvo_replay --drive D --no-error-models --write-tracks T` (the right
observations as the front end measured them) and the drive's injected error D/gt/rig_error.csv
(frame, right_roll_deg, right_pitch_deg, right_yaw_deg; the renderer turns the right camera by
T_c1nom_c1 = Rz(roll) Rx(pitch) Ry(yaw), hil/tools/render/src/drive.cpp), and writes OUT, a copy
of T whose right observations are moved to where the nominal right camera would have seen them:
the ray r = ((uR - cu) / fu, (vR - cv) / fv, 1) of the turned camera is turned back,
r_nom = R r, and projected. Only the axes named by --axes are taken out (the others stay in the
observations), so `--axes yaw` is the rig error the self-calibration does not model. A row that
was not measured (vR_measured 0: vR is a copy of vL) keeps its vR. Then
`sunvo_track_vo OUT out.txt [--self-calib]` runs on it (docs/selfcal.md).
No dependencies beyond Python. Usage: rig_truth_tracks.py TRACKS RIG_ERROR_CSV OUT [--axes
roll,pitch,yaw]
"""
import argparse
import csv
import math
import os
import shutil


def rotation(roll, pitch, yaw):
    """Rz(roll) Rx(pitch) Ry(yaw), angles in rad, as nested lists."""
    def mul(a, b):
        return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]
    cz, sz = math.cos(roll), math.sin(roll)
    cx, sx = math.cos(pitch), math.sin(pitch)
    cy, sy = math.cos(yaw), math.sin(yaw)
    rz = [[cz, -sz, 0.0], [sz, cz, 0.0], [0.0, 0.0, 1.0]]
    rx = [[1.0, 0.0, 0.0], [0.0, cx, -sx], [0.0, sx, cx]]
    ry = [[cy, 0.0, sy], [0.0, 1.0, 0.0], [-sy, 0.0, cy]]
    return mul(mul(rz, rx), ry)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("tracks",
                    help="track folder (calib.txt, times.txt, tracks.csv[, gt_poses.txt])")
    ap.add_argument("rig_error", help="the drive's gt/rig_error.csv")
    ap.add_argument("out", help="the folder to write (created)")
    ap.add_argument("--axes", default="roll,pitch,yaw", help="axes to take out, comma separated")
    a = ap.parse_args()
    axes = set(a.axes.split(","))
    if not axes or not axes <= {"roll", "pitch", "yaw"}:
        raise SystemExit(f"--axes {a.axes}: expected a comma-separated subset of roll,pitch,yaw")
    calib_path = os.path.join(a.tracks, "calib.txt")
    calib = open(calib_path).read().split()
    if len(calib) < 4:
        raise SystemExit(f"{calib_path}:1: expected fu fv cu cv ...")
    fu, fv, cu, cv = (float(x) for x in calib[:4])
    rig = {}
    with open(a.rig_error, newline="") as f:
        rows = csv.reader(f)
        next(rows, None)
        for line, row in enumerate(rows, start=2):
            try:
                k, roll, pitch, yaw = int(row[0]), *(math.radians(float(x)) for x in row[1:4])
            except (ValueError, IndexError):
                raise SystemExit(f"{a.rig_error}:{line}: expected frame and three angles in deg")
            rig[k] = rotation(roll if "roll" in axes else 0.0, pitch if "pitch" in axes else 0.0,
                              yaw if "yaw" in axes else 0.0)
    os.makedirs(a.out, exist_ok=True)
    for name in ("calib.txt", "times.txt", "gt_poses.txt", "sun_cam.csv"):
        if os.path.exists(os.path.join(a.tracks, name)):
            shutil.copyfile(os.path.join(a.tracks, name), os.path.join(a.out, name))
    src = os.path.join(a.tracks, "tracks.csv")
    moved = 0
    with open(src, newline="") as f, open(os.path.join(a.out, "tracks.csv"), "w") as out:
        rows = csv.reader(f)
        header = next(rows, None)
        if header is None or header[:6] != ["frame", "landmark", "uL", "vL", "uR", "vR"]:
            raise SystemExit(f"{src}:1: expected the header frame,landmark,uL,vL,uR,vR")
        out.write(",".join(header) + "\n")
        measured_col = header.index("vR_measured") if "vR_measured" in header else -1
        for line, row in enumerate(rows, start=2):
            try:
                k, uR, vR = int(row[0]), float(row[4]), float(row[5])
            except (ValueError, IndexError):
                raise SystemExit(f"{src}:{line}: expected frame,landmark,uL,vL,uR,vR")
            if k not in rig:
                raise SystemExit(f"{src}:{line}: frame {k} has no row in {a.rig_error}")
            r = rig[k]
            ray = ((uR - cu) / fu, (vR - cv) / fv, 1.0)
            x, y, z = (sum(r[i][j] * ray[j] for j in range(3)) for i in range(3))
            row[4] = f"{fu * x / z + cu:.4f}"
            if measured_col < 0 or row[measured_col] == "1":
                row[5] = f"{fv * y / z + cv:.4f}"
            out.write(",".join(row) + "\n")
            moved += 1
    print(f"wrote {a.out}: {moved} observations, {', '.join(sorted(axes))} taken out")


if __name__ == "__main__":
    main()
