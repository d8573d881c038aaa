#!/usr/bin/env python3
"""Independent reference for sunvo's trajectory metrics (Python standard library only).

Reads a ground-truth and an estimated KITTI pose file (12 numbers per line) and prints, as JSON,
the paper's Table-1 metrics and the KITTI devkit segment errors, computed here from their
definitions with plain lists, quaternions and Python floats - no code shared with the C++
library. Used by tests/eval to cross-check sunvo_eval; also handy by hand:

    scripts/reference_metrics.py GT.txt EST.txt [xz|en]

Definitions (see estimator/metrics/include/sunvo/metrics/metrics.hpp):
  rotations read from a file are replaced by their nearest rotation (as sunvo's loader does);
  both trajectories relative to their own first pose; the difference rotated back into the world
  by the ground truth's first rotation; ARMSE = mean over all poses of the per-pose RMS over the
  axes (3 for translation and rotation vector, 2 in the plane); drift at the last pose; KITTI
  segments every 10 frames for 100..800 m, last frame = first with dist > dist[first] + len.
"""
import bisect
import json
import math
import sys


def read_kitti(path):
    poses = []
    with open(path) as f:
        for line in f:
            v = line.split()
            if not v:
                continue
            if len(v) != 12:
                raise SystemExit(f"{path}: expected 12 fields, got {len(v)}")
            x = [float(t) for t in v]
            R = [[x[0], x[1], x[2]], [x[4], x[5], x[6]], [x[8], x[9], x[10]]]
            poses.append((quat_from_matrix(nearest_rotation(R)), [x[3], x[7], x[11]]))
    return poses


def nearest_rotation(M):
    """Orthogonal polar factor of M (the nearest rotation in the Frobenius norm, as an SVD would
    give), by Newton's iteration R <- (R + R^-T) / 2, which converges quadratically."""
    R = [row[:] for row in M]
    for _ in range(20):
        a, b, c = R[0]
        d, e, f = R[1]
        g, h, i = R[2]
        det = a * (e * i - f * h) - b * (d * i - f * g) + c * (d * h - e * g)
        # inverse transpose = cofactor matrix / det
        cof = [[e * i - f * h, -(d * i - f * g), d * h - e * g],
               [-(b * i - c * h), a * i - c * g, -(a * h - b * g)],
               [b * f - c * e, -(a * f - c * d), a * e - b * d]]
        new = [[0.5 * (R[r][k] + cof[r][k] / det) for k in range(3)] for r in range(3)]
        change = max(abs(new[r][k] - R[r][k]) for r in range(3) for k in range(3))
        R = new
        if change < 1e-17:
            break
    return R


def quat_from_matrix(R):
    """Unit quaternion (w, x, y, z) of a rotation matrix (Shepperd), normalised."""
    tr = R[0][0] + R[1][1] + R[2][2]
    if tr >= R[0][0] and tr >= R[1][1] and tr >= R[2][2]:
        s = 2.0 * math.sqrt(1.0 + tr)
        q = (s / 4, (R[2][1] - R[1][2]) / s, (R[0][2] - R[2][0]) / s, (R[1][0] - R[0][1]) / s)
    elif R[0][0] >= R[1][1] and R[0][0] >= R[2][2]:
        s = 2.0 * math.sqrt(1.0 + R[0][0] - R[1][1] - R[2][2])
        q = ((R[2][1] - R[1][2]) / s, s / 4, (R[0][1] + R[1][0]) / s, (R[0][2] + R[2][0]) / s)
    elif R[1][1] >= R[2][2]:
        s = 2.0 * math.sqrt(1.0 + R[1][1] - R[0][0] - R[2][2])
        q = ((R[0][2] - R[2][0]) / s, (R[0][1] + R[1][0]) / s, s / 4, (R[1][2] + R[2][1]) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + R[2][2] - R[0][0] - R[1][1])
        q = ((R[1][0] - R[0][1]) / s, (R[0][2] + R[2][0]) / s, (R[1][2] + R[2][1]) / s, s / 4)
    n = math.sqrt(sum(c * c for c in q))
    return tuple(c / n for c in q)


def qmul(a, b):
    return (a[0] * b[0] - a[1] * b[1] - a[2] * b[2] - a[3] * b[3],
            a[0] * b[1] + a[1] * b[0] + a[2] * b[3] - a[3] * b[2],
            a[0] * b[2] - a[1] * b[3] + a[2] * b[0] + a[3] * b[1],
            a[0] * b[3] + a[1] * b[2] - a[2] * b[1] + a[3] * b[0])


def qconj(q):
    return (q[0], -q[1], -q[2], -q[3])


def qrot(q, v):
    r = qmul(qmul(q, (0.0, v[0], v[1], v[2])), qconj(q))
    return [r[1], r[2], r[3]]


def qangle(q):
    return 2.0 * math.atan2(math.sqrt(q[1] ** 2 + q[2] ** 2 + q[3] ** 2), abs(q[0]))


def sub(a, b):
    return [a[0] - b[0], a[1] - b[1], a[2] - b[2]]


def norm(v):
    return math.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2)


def relative(pose_i, pose_j):
    """T_i^-1 T_j as (q, t)."""
    qi, ti = pose_i
    qj, tj = pose_j
    return qmul(qconj(qi), qj), qrot(qconj(qi), sub(tj, ti))


def table1(gt, est, plane):
    ia, ib = (0, 1) if plane == "en" else (0, 2)
    n = len(gt)
    s_t = s_p = s_r = 0.0
    for k in range(n):
        qg, tg = relative(gt[0], gt[k])
        qe, te = relative(est[0], est[k])
        d = qrot(gt[0][0], sub(te, tg))
        dp = math.hypot(d[ia], d[ib])
        s_t += norm(d) / math.sqrt(3.0)
        s_p += dp / math.sqrt(2.0)
        s_r += qangle(qmul(qe, qconj(qg))) / math.sqrt(3.0)
    length = sum(norm(sub(gt[k][1], gt[k - 1][1])) for k in range(1, n))
    return {
        "trans_armse_m": s_t / n,
        "trans_armse_plane_m": s_p / n,
        "rot_armse_rad": s_r / n,
        "gt_path_length_m": length,
        "final_drift_m": norm(d),
        "final_drift_pct": 100.0 * norm(d) / length,
        "final_drift_plane_m": dp,
        "final_drift_plane_pct": 100.0 * dp / length,
    }


def kitti_segments(gt, est):
    dist = [0.0]
    for k in range(1, len(gt)):
        dist.append(dist[-1] + norm(sub(gt[k][1], gt[k - 1][1])))
    t_sum = r_sum = 0.0
    count = 0
    for first in range(0, len(gt), 10):
        for length in (100, 200, 300, 400, 500, 600, 700, 800):
            # first index >= first with dist > dist[first] + length (dist is non-decreasing)
            last = bisect.bisect_right(dist, dist[first] + length, lo=first)
            if last >= len(gt):
                continue
            qg, tg = relative(gt[first], gt[last])
            qe, te = relative(est[first], est[last])
            # E = dgt^-1 dest: rotation qg^* qe, translation qg^* (te - tg).
            t_sum += norm(qrot(qconj(qg), sub(te, tg))) / length
            r_sum += qangle(qmul(qconj(qg), qe)) / length
            count += 1
    return {
        "num_segments": count,
        "t_err_pct": 100.0 * t_sum / count if count else None,
        "r_err_deg_per_m": math.degrees(r_sum / count) if count else None,
    }


def main():
    if len(sys.argv) not in (3, 4):
        sys.stderr.write(__doc__)
        return 2
    gt = read_kitti(sys.argv[1])
    est = read_kitti(sys.argv[2])
    plane = sys.argv[3] if len(sys.argv) == 4 else "xz"
    if len(gt) != len(est) or len(gt) < 2:
        sys.stderr.write("trajectories must have the same length >= 2\n")
        return 2
    json.dump({"table1": table1(gt, est, plane), "kitti_segments": kitti_segments(gt, est)},
              sys.stdout, indent=2)
    sys.stdout.write("\n")
    return 0


if __name__ == "__main__":
    sys.exit(main())
