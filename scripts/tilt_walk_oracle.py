#!/usr/bin/env python3
"""Would a tilt walk per camera axis (pitch and roll apart) follow VO's tilt better than one walk?

Usage: scripts/tilt_walk_oracle.py GT.txt RUN.txt [--up x,y,z] [--cue-sigma-deg S] [--every F]
                                   [--draws D] [--walks-deg q1,q2,...] [--seed N]
GT and RUN are KITTI pose files (T_w_c, 12 numbers a line) of the same frames, RUN a pure VO run
(e.g. route_<id>_run0.txt of `sunvo_experiment --write-poses`). Pure Python, no dependencies.

The run's world tilt error e_k (C_w,gt = Exp(w) C_w,run, w less its part about up, two
coordinates in the plane normal to up) is the truth a Kalman filter has to follow. Every F-th
frame the filter gets an answer e_k + n, n ~ N(0, S^2 I) (an unbiased cue of S per axis, drawn D
times), and between answers its covariance grows by a walk, either
  one walk:      Q = q^2 I                          (the fusion's tilt walk, walk_bank.hpp)
  per axis:      Q = M diag(q_p^2, 0, q_r^2) M^T    (M = the tilt plane's axes times C_w_c:
                                                      pitch about the camera's x, roll about z)
for every q (and every pair q_p, q_r) of the grid. It prints, for each, the tilt RMS left (mean
over the draws) and the height the residual tilt r_k builds (RMS over the draws of
-sum_k (r_k x s_k) . up, s_k the true step; the same sum as pose_error_split.py). The best walk
of each kind is chosen with hindsight on this very run: an oracle, an upper bound on what a bank
that learns the walks per axis could gain over one that learns one walk."""
import argparse
import math
import random

from pose_error_split import (cross, dot, height_from_tilt, load, log_so3, mul, transpose,
                              unit_up)


def mat2_inv(a):
    det = a[0][0] * a[1][1] - a[0][1] * a[1][0]
    return [[a[1][1] / det, -a[0][1] / det], [-a[1][0] / det, a[0][0] / det]]


def mat2_mul(a, b):
    return [[a[i][0] * b[0][j] + a[i][1] * b[1][j] for j in range(2)] for i in range(2)]


def plane_axes(up):
    """Two unit vectors spanning the plane normal to up."""
    seed = [1.0, 0.0, 0.0] if abs(up[0]) < 0.9 else [0.0, 0.0, 1.0]
    d = dot(seed, up)
    a = [seed[i] - d * up[i] for i in range(3)]
    n = math.sqrt(dot(a, a))
    a = [x / n for x in a]
    return a, cross(up, a)


def follow(errors, walks, steps, up, axes, sigma, every, draws, seed):
    """Runs the filter with walk covariances walks[k] (2x2 per frame) over every draw; returns
    (mean tilt RMS [rad], RMS of the height built [m])."""
    rng = random.Random(seed)
    noise = [[(rng.gauss(0.0, sigma), rng.gauss(0.0, sigma)) for _ in errors] for _ in range(draws)]
    x = [[0.0, 0.0] for _ in range(draws)]
    p = [[math.radians(1.0) ** 2, 0.0], [0.0, math.radians(1.0) ** 2]]
    sum_sq = [0.0] * draws
    built = [0.0] * draws
    for k, e in enumerate(errors):
        if k > 0:
            q = walks[k]
            p = [[p[i][j] + q[i][j] for j in range(2)] for i in range(2)]
        if k > 0 and k % every == 0:
            s = [[p[i][j] + (sigma * sigma if i == j else 0.0) for j in range(2)] for i in range(2)]
            gain = mat2_mul(p, mat2_inv(s))
            p = [[p[i][j] - sum(gain[i][m] * p[m][j] for m in range(2)) for j in range(2)]
                 for i in range(2)]
            for d in range(draws):
                nu = [e[i] + noise[d][k][i] - x[d][i] for i in range(2)]
                x[d] = [x[d][i] + gain[i][0] * nu[0] + gain[i][1] * nu[1] for i in range(2)]
        for d in range(draws):
            r = [e[0] - x[d][0], e[1] - x[d][1]]
            sum_sq[d] += r[0] * r[0] + r[1] * r[1]
            if k < len(steps):
                r3 = [r[0] * axes[0][i] + r[1] * axes[1][i] for i in range(3)]
                built[d] += height_from_tilt(r3, steps[k], up)
    tilt = sum(math.sqrt(v / len(errors)) for v in sum_sq) / draws
    return tilt, math.sqrt(sum(b * b for b in built) / draws)


def drift_per_axis(gt, w, span=100):
    """VO's attitude drift in the camera's axes: the mean per-frame change of its world error w
    (one per frame of gt) taken in the camera (C_c_w dw), pitch (x) and roll (z), and what walks
    around that mean: the RMS over windows of `span` frames of the summed change less its mean,
    over sqrt(span)."""
    sums = [[0.0, 0.0]]
    for k in range(len(w) - 1):
        dw = [w[k + 1][i] - w[k][i] for i in range(3)]
        c = [sum(gt[k][0][m][a] * dw[m] for m in range(3)) for a in (0, 2)]  # C_c_w dw
        sums.append([sums[-1][a] + c[a] for a in range(2)])
    frames = len(w) - 1
    if frames < 1:
        return "drift per axis: too few frames"
    mean = [sums[-1][a] / frames for a in range(2)]
    span = min(span, frames)
    walk = []
    for a in range(2):
        d = [sums[k + span][a] - sums[k][a] - span * mean[a] for k in range(len(sums) - span)]
        walk.append(math.sqrt(sum(x * x for x in d) / len(d) / span))
    return (f"drift in the camera: mean pitch {math.degrees(mean[0]):+.4f}, roll "
            f"{math.degrees(mean[1]):+.4f} deg/frame; around it, over {span} frames, pitch "
            f"{math.degrees(walk[0]):.3f}, roll {math.degrees(walk[1]):.3f} deg/sqrt(frame)")


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("gt")
    parser.add_argument("run")
    parser.add_argument("--up", default="0,-1,0")
    parser.add_argument("--cue-sigma-deg", type=float, default=1.0)
    parser.add_argument("--every", type=int, default=5)
    parser.add_argument("--draws", type=int, default=12)
    parser.add_argument("--walks-deg", default="0.0055,0.011,0.024,0.05,0.1,0.2")
    parser.add_argument("--seed", type=int, default=1)
    args = parser.parse_args()
    if args.cue_sigma_deg <= 0.0 or args.every < 1 or args.draws < 1:
        raise SystemExit("--cue-sigma-deg must be > 0, --every and --draws >= 1")
    try:
        grid = [math.radians(float(v)) for v in args.walks_deg.split(",")]
    except ValueError:
        raise SystemExit(f"--walks-deg: not a list of numbers: '{args.walks_deg}'")
    if not grid or min(grid) <= 0.0:
        raise SystemExit("--walks-deg: every walk must be > 0")
    up = unit_up(args.up)
    axes = plane_axes(up)
    gt, run = load(args.gt), load(args.run)
    if len(run) != len(gt):
        raise SystemExit(f"{args.run}: {len(run)} poses, the ground truth has {len(gt)}")
    steps = [[b[1][i] - a[1][i] for i in range(3)] for a, b in zip(gt, gt[1:])]
    w_all = [log_so3(mul(r_gt, transpose(r))) for (r_gt, _), (r, _) in zip(gt, run)]
    errors, cam, vo_built = [], [], 0.0
    for k, ((r_gt, _), w) in enumerate(zip(gt, w_all)):
        e = [dot(w, axes[0]), dot(w, axes[1])]
        errors.append(e)
        if k < len(steps):
            w3 = [e[0] * axes[0][i] + e[1] * axes[1][i] for i in range(3)]
            vo_built += height_from_tilt(w3, steps[k], up)
        # The camera's x (pitch) and z (roll) axes in the tilt plane: rows of axes * C_w_c.
        cam.append([[dot(axes[i], [r_gt[m][c] for m in range(3)]) for c in (0, 2)]
                    for i in range(2)])
    vo_tilt = math.sqrt(sum(e[0] ** 2 + e[1] ** 2 for e in errors) / len(errors))
    print(drift_per_axis(gt, w_all))
    print(f"{args.run}: pure VO tilt RMS {math.degrees(vo_tilt):.3f} deg, height built by the "
          f"tilt {vo_built:+.2f} m; cue {args.cue_sigma_deg:g} deg every {args.every} frames, "
          f"{args.draws} draws")
    sigma = math.radians(args.cue_sigma_deg)
    results = []
    for q in grid:
        walks = [[[q * q, 0.0], [0.0, q * q]]] * len(errors)
        results.append(("one walk", (q,), *follow(errors, walks, steps, up, axes, sigma,
                                                  args.every, args.draws, args.seed)))
    for qp in grid:
        for qr in grid:
            walks = [[[qp * qp * m[i][0] * m[j][0] + qr * qr * m[i][1] * m[j][1] for j in range(2)]
                      for i in range(2)] for m in cam]
            results.append(("per axis", (qp, qr), *follow(errors, walks, steps, up, axes, sigma,
                                                          args.every, args.draws, args.seed)))
    for kind, qs, tilt, height in results:
        walk = " / ".join(f"{math.degrees(q):.4f}" for q in qs)
        print(f"  {kind} {walk} deg/frame: tilt RMS {math.degrees(tilt):.3f} deg, "
              f"height built RMS {height:.2f} m")
    for kind in ("one walk", "per axis"):
        best = min((r for r in results if r[0] == kind), key=lambda r: r[2])
        walk = " / ".join(f"{math.degrees(q):.4f}" for q in best[1])
        print(f"best {kind}: {walk} deg/frame, tilt RMS {math.degrees(best[2]):.3f} deg, "
              f"height built RMS {best[3]:.2f} m")


if __name__ == "__main__":
    main()
