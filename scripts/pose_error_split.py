#!/usr/bin/env python3
"""Splits a run's pose error by gravity: height and horizontal position error, tilt and heading
attitude error, the mean attitude error in the camera's own axes, and the height the tilt error
built.

Usage: scripts/pose_error_split.py GT.txt RUN.txt [RUN.txt ...] [--up x,y,z]
                                   [--cue-sigma-deg S --answers N]
GT and RUN are KITTI pose files (12 numbers per line, T_w_c) of the same frames, e.g. those of
`sunvo_experiment --write-poses` (route_<id>_gt.txt, route_<id>_run<i>.txt). --up is the world's
up (default 0,-1,0: KITTI's first camera). Pure Python, no dependencies.

Height built by the tilt: a run whose world attitude is off by w (C_w,gt = Exp(w) C_w,run) moves
each true step s by about -w x s, so its tilt part w_t (w less its part about up) builds the
height error sum over steps of (-w_t x s) . up. What is left of the final height error is the
steps' own (their length and direction in the camera).
The cue's floor (with --cue-sigma-deg and --answers): a filter that corrects the tilt with N
unbiased answers of per-axis std S leaves, whatever its gain, every answer's error in the sum of
its tilt errors over the route (e_k = (1 - K) e_{k-1} + K n_k sums to about sum n_k), so the
height it builds over a route of length L has a std of about S L / sqrt(N): a run whose own final
height error is below that cannot be expected to gain height from such a cue."""
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


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def unit_up(text):
    """The world's up from "x,y,z", normalised."""
    up = [float(x) for x in text.split(",")]
    norm = math.sqrt(dot(up, up))
    return [x / norm for x in up]


def height_from_tilt(w_t, step, up):
    """The height a tilt error w_t (C_w,gt = Exp(w) C_w,est, its part normal to up) adds to a true
    step: the step is walked turned by -w_t."""
    return -dot(cross(w_t, step), up)


def rms(values):
    return math.sqrt(sum(x * x for x in values) / len(values))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("gt")
    parser.add_argument("runs", nargs="+")
    parser.add_argument("--up", default="0,-1,0")
    parser.add_argument("--cue-sigma-deg", type=float, default=0.0)
    parser.add_argument("--answers", type=int, default=0)
    args = parser.parse_args()
    if (args.cue_sigma_deg > 0.0) != (args.answers > 0):
        raise SystemExit("--cue-sigma-deg and --answers go together (both > 0)")
    up = unit_up(args.up)
    gt = load(args.gt)
    steps = [[b[1][i] - a[1][i] for i in range(3)] for a, b in zip(gt, gt[1:])]
    length = sum(math.sqrt(dot(st, st)) for st in steps)
    if args.answers > 0:
        floor = math.radians(args.cue_sigma_deg) * length / math.sqrt(args.answers)
        print(f"{args.gt}: route {length:.1f} m; the cue's height floor "
              f"{args.cue_sigma_deg:g} deg x {length:.1f} m / sqrt({args.answers}) = {floor:.2f} m")
    for path in args.runs:
        run = load(path)
        if len(run) != len(gt):
            raise SystemExit(f"{path}: {len(run)} poses, the ground truth has {len(gt)}")
        height, horiz, tilt, heading = [], [], [], []
        mean_c = [0.0, 0.0, 0.0]
        built = 0.0
        for k, ((r_gt, t_gt), (r, t)) in enumerate(zip(gt, run)):
            e = [t[i] - t_gt[i] for i in range(3)]
            h = dot(e, up)
            height.append(h)
            horiz.append(math.sqrt(max(0.0, dot(e, e) - h * h)))
            w = log_so3(mul(r_gt, transpose(r)))  # C_w,gt = Exp(w) C_w,est
            hd = dot(w, up)
            heading.append(math.degrees(hd))
            w_t = [w[i] - hd * up[i] for i in range(3)]  # the tilt part
            tilt.append(math.degrees(math.sqrt(dot(w_t, w_t))))
            if k < len(steps):
                built += height_from_tilt(w_t, steps[k], up)
            c_c_w = transpose(r_gt)
            for i in range(3):
                mean_c[i] += math.degrees(dot(c_c_w[i], w)) / len(gt)
        print(f"{path}: height error RMS {rms(height):.2f} m, final {height[-1]:+.2f} m; "
              f"horizontal RMS {rms(horiz):.2f} m, final {horiz[-1]:.2f} m; tilt RMS "
              f"{rms(tilt):.2f} deg, heading RMS {rms(heading):.2f} deg; mean attitude error in "
              f"the camera: pitch (x) {mean_c[0]:+.3f} deg, roll (z) {mean_c[2]:+.3f} deg; "
              f"height built by the tilt {built:+.2f} m")


if __name__ == "__main__":
    main()
