#!/usr/bin/env python3
"""Where a track folder's row residual under the true motion comes from (docs/backend.md).

For every landmark seen in frames k-1 and k: triangulated from its stereo pair in k-1 (depth
z = fu b / (uL - uR)), moved by the ground truth's T_k,k-1, projected into k; the residual is the
observed vL minus the projected row. Printed per depth bin: the median over all observations, over
those above the principal row (v - cv < -20 px) and those below it (> +20 px). A principal-point
error or a translation tilted in the camera gives a part proportional to 1/z with one sign above
and below; an error of the depth (a disparity bias) gives one proportional to (v - cv) / z, whose
sign flips across the principal row.

With --vo POSES (a KITTI pose file of the same frames, e.g. sunvo_track_vo's output) it also
prints the median pitch of the per-frame translation direction in the camera, atan2(t_y, t_z) of
T_k-1,k, for the ground truth and the estimate (a principal-point error of d px or a tilted
translation would put d / fv between the two), and the mean per-frame differences, estimate minus
truth, of T_k,k-1's vertical translation t_y and of its rotation about the camera's x axis: what
the two motions' row predictions differ by (fv t_y / z and fv times the angle). With --under POSES
the residual is taken under that file's motion instead of the truth's.

Pure Python (no numpy): python3 scripts/track_motion_check.py FOLDER [--vo POSES] [--under POSES]
"""
import argparse
import math
import statistics
import sys

# The pose files' reader and the rotation helpers are pose_error_split.py's (this folder).
from pose_error_split import load, mul, transpose

BINS = (5.0, 10.0, 15.0, 20.0, 30.0, 60.0, math.inf)
SIDE_PX = 20.0


def fail(msg):
    sys.stderr.write(f"track_motion_check: {msg}\n")
    sys.exit(1)


def numbers(path, line_no, text, count):
    try:
        values = [float(x) for x in text.replace(",", " ").split()]
    except ValueError:
        fail(f"{path}:{line_no}: not a number in '{text.strip()}'")
    if len(values) != count:
        fail(f"{path}:{line_no}: expected {count} numbers, got {len(values)}")
    return values


def relative(pose_a, pose_b):
    """T_a^-1 T_b: pose b in frame a."""
    ra_t = transpose(pose_a[0])
    d = [b - a for a, b in zip(pose_a[1], pose_b[1])]
    return mul(ra_t, pose_b[0]), [sum(ra_t[i][k] * d[k] for k in range(3)) for i in range(3)]


def apply(pose, p):
    r, t = pose
    return [sum(r[i][j] * p[j] for j in range(3)) + t[i] for i in range(3)]


def read_tracks(path):
    frames = {}
    try:
        with open(path) as f:
            for i, line in enumerate(f, 1):
                if not line.strip() or not (line[0].isdigit() or line[0] == "-"):
                    continue
                v = numbers(path, i, line, 6)
                frames.setdefault(int(v[0]), {})[int(v[1])] = v[2:6]
    except OSError as e:
        fail(f"{path}: {e.strerror}")
    return frames


def median_or_none(values):
    return statistics.median(values) if values else None


def fmt(value, n):
    return "   -   (n 0)" if value is None else f"{value:+.3f} (n {n})"


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folder", help="track folder: calib.txt, gt_poses.txt, tracks.csv")
    ap.add_argument("--vo", help="a KITTI pose file of the same frames")
    ap.add_argument("--under", help="take the residual under this pose file's motion")
    args = ap.parse_args()
    calib_path = f"{args.folder}/calib.txt"
    try:
        with open(calib_path) as f:
            fu, fv, cu, cv, base = numbers(calib_path, 1, f.readline(), 5)
    except OSError as e:
        fail(f"{calib_path}: {e.strerror}")
    gt = load(f"{args.folder}/gt_poses.txt")
    tracks = read_tracks(f"{args.folder}/tracks.csv")
    motion = gt
    if args.under:
        motion = load(args.under)
        if len(motion) != len(gt):
            fail(f"{args.under}: {len(motion)} poses, the ground truth has {len(gt)}")

    # (bin, side) -> residuals; side 0 all, 1 above, 2 below the principal row.
    res = {(b, s): [] for b in range(len(BINS) - 1) for s in range(3)}
    for k in range(1, len(motion)):
        prev, cur = tracks.get(k - 1, {}), tracks.get(k, {})
        T_k_km1 = relative(motion[k], motion[k - 1])
        for lm, (u, v, ur, _vr) in prev.items():
            if lm not in cur or u - ur < 1.0:
                continue
            z = fu * base / (u - ur)
            q = apply(T_k_km1, [(u - cu) * z / fu, (v - cv) * z / fv, z])
            if q[2] < 1.0:
                continue
            r = cur[lm][1] - (cv + fv * q[1] / q[2])
            for b in range(len(BINS) - 1):
                if BINS[b] <= z < BINS[b + 1]:
                    res[(b, 0)].append(r)
                    if v - cv < -SIDE_PX:
                        res[(b, 1)].append(r)
                    elif v - cv > SIDE_PX:
                        res[(b, 2)].append(r)
    which = f"the motion of {args.under}" if args.under else "the true motion"
    print(f"row residual under {which} [px], median by depth in k-1:")
    for b in range(len(BINS) - 1):
        lo, hi = BINS[b], BINS[b + 1]
        span = f"{lo:.0f}-{hi:.0f} m" if hi < math.inf else f"> {lo:.0f} m"
        cells = [fmt(median_or_none(res[(b, s)]), len(res[(b, s)])) for s in range(3)]
        print(f"  {span:9s} all {cells[0]}, above the principal row {cells[1]}, below {cells[2]}")

    if args.vo:
        vo = load(args.vo)
        if len(vo) != len(gt):
            fail(f"{args.vo}: {len(vo)} poses, the ground truth has {len(gt)}")
        pitch_gt, pitch_vo, diff = [], [], []
        d_ty, d_rx = [], []
        for k in range(1, len(gt)):
            r_gt, t_gt_k = relative(gt[k], gt[k - 1])
            r_vo, t_vo_k = relative(vo[k], vo[k - 1])
            d_ty.append(t_vo_k[1] - t_gt_k[1])
            # R_vo R_gt^T, its small angle about x: (m[2][1] - m[1][2]) / 2.
            m = mul(r_vo, transpose(r_gt))
            d_rx.append(0.5 * (m[2][1] - m[1][2]))
            t_gt = relative(gt[k - 1], gt[k])[1]
            t_vo = relative(vo[k - 1], vo[k])[1]
            if math.hypot(*t_gt) < 0.3 or math.hypot(*t_vo) < 0.3:
                continue
            a, e = math.atan2(t_gt[1], t_gt[2]), math.atan2(t_vo[1], t_vo[2])
            pitch_gt.append(a)
            pitch_vo.append(e)
            diff.append(e - a)
        if not diff:
            fail("no frame moves 0.3 m or more")
        print(f"translation direction pitch atan2(t_y, t_z), median over {len(diff)} frames: "
              f"truth {1e3 * statistics.median(pitch_gt):+.2f} mrad, "
              f"estimate {1e3 * statistics.median(pitch_vo):+.2f} mrad, "
              f"estimate - truth {1e3 * statistics.median(diff):+.2f} mrad")
        print(f"T_k,k-1 estimate - truth, mean (median) over {len(d_ty)} frames: vertical "
              f"translation t_y {1e3 * statistics.fmean(d_ty):+.2f} "
              f"({1e3 * statistics.median(d_ty):+.2f}) mm, rotation about x "
              f"{1e3 * statistics.fmean(d_rx):+.3f} ({1e3 * statistics.median(d_rx):+.3f}) mrad")


if __name__ == "__main__":
    try:
        main()
    except BrokenPipeError:  # the output piped into head
        sys.exit(0)
