#!/usr/bin/env python3
"""Splits a run's pose error by gravity: height and horizontal position error, tilt and heading
attitude error, and the mean attitude error in the camera's own axes.

Usage: scripts/pose_error_split.py GT.txt RUN.txt [RUN.txt ...] [--up x,y,z]
GT and RUN are KITTI pose files (12 numbers per line, T_w_c) of the same frames, e.g. those of
`sunvo_experiment --write-poses` (route_<id>_gt.txt, route_<id>_run<i>.txt). --up is the world's
up (default 0,-1,0: KITTI's first camera). Pure Python, no dependencies."""
import argparse
import math


def load(path):
    poses = []
    try:
        with open(path) as f:
            for number, line in enumerate(f, 1):
                v = line.split()
                if len(v) != 12:
                    raise SystemExit(f"{path}:{number}: expected 12 numbers, got {len(v)}")
                try:
                    v = [float(x) for x in v]
                except ValueError:
                    raise SystemExit(f"{path}:{number}: not a number in '{line.strip()}'")
                poses.append(([v[0:3], v[4:7], v[8:11]], [v[3], v[7], v[11]]))
    except OSError as e:
        raise SystemExit(f"{path}: {e.strerror}")
    return poses


def mul(a, b):
    return [[sum(a[i][k] * b[k][j] for k in range(3)) for j in range(3)] for i in range(3)]


def transpose(a):
    return [[a[j][i] for j in range(3)] for i in range(3)]


def log_so3(r):
    c = max(-1.0, min(1.0, (r[0][0] + r[1][1] + r[2][2] - 1.0) / 2.0))
    th = math.acos(c)
    if th < 1e-12:
        return [0.0, 0.0, 0.0]
    s = 2.0 * math.sin(th)
    return [(r[2][1] - r[1][2]) / s * th, (r[0][2] - r[2][0]) / s * th,
            (r[1][0] - r[0][1]) / s * th]


def dot(a, b):
    return sum(x * y for x, y in zip(a, b))


def rms(values):
    return math.sqrt(sum(x * x for x in values) / len(values))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("gt")
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--up", default="0,-1,0")
    args = parser.parse_args()
    up = [float(x) for x in args.up.split(",")]
    norm = math.sqrt(dot(up, up))
    up = [x / norm for x in up]
    gt = load(args.gt)
    for path in args.runs:
        run = load(path)
        if len(run) != len(gt):
            raise SystemExit(f"{path}: {len(run)} poses, the ground truth has {len(gt)}")
        height, horiz, tilt, heading = [], [], [], []
        mean_c = [0.0, 0.0, 0.0]
        for (r_gt, t_gt), (r, t) in zip(gt, run):
            e = [t[i] - t_gt[i] for i in range(3)]
            h = dot(e, up)
            height.append(h)
            horiz.append(math.sqrt(max(0.0, dot(e, e) - h * h)))
            w = log_so3(mul(r_gt, transpose(r)))  # C_w,gt = Exp(w) C_w,est
            hd = dot(w, up)
            heading.append(math.degrees(hd))
            tilt.append(math.degrees(math.sqrt(max(0.0, dot(w, w) - hd * hd))))
            c_c_w = transpose(r_gt)
            for i in range(3):
                mean_c[i] += math.degrees(dot(c_c_w[i], w)) / len(gt)
        print(f"{path}: height error RMS {rms(height):.2f} m, final {height[-1]:+.2f} m; "
              f"horizontal RMS {rms(horiz):.2f} m, final {horiz[-1]:.2f} m; tilt RMS "
              f"{rms(tilt):.2f} deg, heading RMS {rms(heading):.2f} deg; mean attitude error in "
              f"the camera: pitch (x) {mean_c[0]:+.3f} deg, roll (z) {mean_c[2]:+.3f} deg")


if __name__ == "__main__":
    main()
