#!/usr/bin/env python3
"""A track folder as the same stereo rig would see it turned against the vehicle.

A rover's camera is rarely mounted level and straight ahead: it looks down at the ground in front
of it, or a little to the side. The window's non-holonomic rows learn that turn (the slopes beta
and gamma, docs/vertical_prior.md, "A camera turned against the vehicle"); this makes the data to
check it on from a real folder. The rig turns as a whole (the right camera stays at (b, 0, 0) in
the left one's frame), so the scene turns the other way: every observation is back-projected with
its disparity, X' = R X with R a turn by DEG about the camera's x axis (--axis x: a pitch;
positive moves the scene up in the image, i.e. the camera looks down) or y axis (--axis y: a
yaw), and projected again by the same rectified rig. The principal point moves so that every
observation keeps a non-negative column and row, and calib.txt gets the enlarged size (7 fields).
gt_poses.txt becomes R T R^T per frame (the first camera stays the world), sun_cam.csv (if
present) R s; vR keeps its offset from vL. Observations without a positive disparity (no depth to
turn) or that end nearer than 1 m are left out and counted. No dependencies beyond Python.
Usage: turn_rig_tracks.py TRACKS OUT DEG [--axis x|y]
"""
import argparse
import math
import os
import shutil
import sys


def fail(msg):
    sys.exit(f"turn_rig_tracks.py: {msg}")


def read_lines(path):
    try:
        with open(path) as f:
            return f.read().splitlines()
    except OSError as e:
        fail(f"{path}: {e.strerror}")


def numbers(path, line_no, text, names):
    fields = text.replace(",", " ").split()
    if len(fields) != len(names):
        fail(f"{path}:{line_no}: expected {len(names)} fields ({' '.join(names)}), got {len(fields)}")
    out = []
    for name, field in zip(names, fields):
        try:
            value = float(field)
        except ValueError:
            fail(f"{path}:{line_no}: field '{name}': not a number: {field}")
        if not math.isfinite(value):
            fail(f"{path}:{line_no}: field '{name}': not finite: {field}")
        out.append(value)
    return out


def rotation(axis, deg):
    a = math.radians(deg)
    c, s = math.cos(a), math.sin(a)
    if axis == "x":
        return [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]
    return [[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]]


def mat_vec(R, v):
    return [sum(R[i][j] * v[j] for j in range(3)) for i in range(3)]


def mat_mul(A, B):
    return [[sum(A[i][k] * B[k][j] for k in range(len(B))) for j in range(len(B[0]))]
            for i in range(len(A))]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("tracks")
    parser.add_argument("out")
    parser.add_argument("deg", type=float, help="the turn, degrees, in (-45, 45)")
    parser.add_argument("--axis", choices=("x", "y"), default="x",
                        help="x: pitch (positive looks down), y: yaw (positive looks right)")
    args = parser.parse_args()
    if not (-45.0 < args.deg < 45.0):
        fail(f"DEG must be in (-45, 45): {args.deg}")
    src = args.tracks
    calib_path = os.path.join(src, "calib.txt")
    calib = [l for l in read_lines(calib_path) if l.strip()]
    if not calib:
        fail(f"{calib_path}:1: empty")
    n = len(calib[0].split())
    if n not in (5, 7):
        fail(f"{calib_path}:1: expected 5 fields 'fu fv cu cv baseline_m' or 7 with 'width height'")
    fu, fv, cu, cv, b = numbers(calib_path, 1, " ".join(calib[0].split()[:5]),
                                ("fu", "fv", "cu", "cv", "baseline_m"))
    R = rotation(args.axis, args.deg)

    tracks_path = os.path.join(src, "tracks.csv")
    lines = read_lines(tracks_path)
    if not lines or lines[0].replace(" ", "") != "frame,landmark,uL,vL,uR,vR":
        fail(f"{tracks_path}:1: expected the header 'frame,landmark,uL,vL,uR,vR'")
    names = ("frame", "landmark", "uL", "vL", "uR", "vR")
    rows, behind, no_depth = [], 0, 0
    for i, text in enumerate(lines[1:], start=2):
        if not text.strip():
            continue
        f, lm, uL, vL, uR, vR = numbers(tracks_path, i, text, names)
        d = uL - uR
        if d <= 0.0:  # no depth to turn (a mismatch the odometry's RANSAC would refuse)
            no_depth += 1
            continue
        z = fu * b / d
        X = mat_vec(R, [(uL - cu) / fu * z, (vL - cv) / fv * z, z])
        if X[2] < 1.0:
            behind += 1
            continue
        rows.append((int(f), int(lm), fu * X[0] / X[2], fv * X[1] / X[2],
                     fu * (X[0] - b) / X[2], vR - vL))
    if not rows:
        fail(f"{tracks_path}: no observation left")
    du = max(0.0, 1.0 - cu - min(min(r[2], r[4]) for r in rows))
    dv = max(0.0, 1.0 - cv - min(min(r[3], r[3] + r[5]) for r in rows))
    cu2, cv2 = cu + du, cv + dv
    width = int(math.ceil(max(max(r[2], r[4]) for r in rows) + cu2)) + 2
    height = int(math.ceil(max(max(r[3], r[3] + r[5]) for r in rows) + cv2)) + 2
    width, height = max(width, int(2 * cu2) + 2), max(height, int(2 * cv2) + 2)

    os.makedirs(args.out, exist_ok=True)
    with open(os.path.join(args.out, "tracks.csv"), "w") as o:
        o.write("frame,landmark,uL,vL,uR,vR\n")
        for f, lm, x, y, xr, dvr in rows:
            o.write(f"{f},{lm},{x + cu2:.3f},{y + cv2:.3f},{xr + cu2:.3f},{y + cv2 + dvr:.3f}\n")
    with open(os.path.join(args.out, "calib.txt"), "w") as o:
        o.write(f"{fu:.6f} {fv:.6f} {cu2:.6f} {cv2:.6f} {b:.9f} {width} {height}\n")

    gt_path = os.path.join(src, "gt_poses.txt")
    if os.path.isfile(gt_path):
        Rt = [list(r) for r in zip(*R)]
        with open(os.path.join(args.out, "gt_poses.txt"), "w") as o:
            for i, text in enumerate(read_lines(gt_path), start=1):
                if not text.strip():
                    continue
                p = numbers(gt_path, i, text, [f"T{k // 4}{k % 4}" for k in range(12)])
                C = [p[0:3], p[4:7], p[8:11]]
                t = [p[3], p[7], p[11]]
                C2 = mat_mul(mat_mul(R, C), Rt)
                t2 = mat_vec(R, t)
                o.write(" ".join(f"{v:.9e}" for r in range(3) for v in (*C2[r], t2[r])) + "\n")
    sun_path = os.path.join(src, "sun_cam.csv")
    if os.path.isfile(sun_path):
        sun = read_lines(sun_path)
        with open(os.path.join(args.out, "sun_cam.csv"), "w") as o:
            o.write(sun[0] + "\n")
            for i, text in enumerate(sun[1:], start=2):
                if not text.strip():
                    continue
                f, sx, sy, sz = numbers(sun_path, i, text, ("frame", "sx", "sy", "sz"))
                s2 = mat_vec(R, [sx, sy, sz])
                o.write(f"{int(f)},{s2[0]:.9f},{s2[1]:.9f},{s2[2]:.9f}\n")
    if os.path.isfile(os.path.join(src, "times.txt")):
        shutil.copy(os.path.join(src, "times.txt"), os.path.join(args.out, "times.txt"))
    print(f"turn_rig_tracks.py: {len(rows)} observations turned by {args.deg:g} deg about "
          f"{args.axis}; left out: {no_depth} without a positive disparity, {behind} nearer than 1 m; "
          f"image {width}x{height}, "
          f"principal point ({cu2:.1f}, {cv2:.1f})")


if __name__ == "__main__":
    main()
