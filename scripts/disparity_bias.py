#!/usr/bin/env python3
"""A track folder's constant disparity bias, measured against poses: the stereo error VO hardly sees.

A right camera turned by a small yaw, or a right principal point a few tenths of a pixel off, adds
the same offset a to every disparity: d = fu b / z + a. Near points hardly notice it, far points
are placed too far (a < 0) or too near, and VO's steps come out long or short by the scene's
depths. Measured here from the left image and a set of poses alone: each landmark seen in three
or more frames over at least MIN_PARALLAX degrees is triangulated from its left rays (the poses
T_w_c of POSES), every observation that reprojects within 1 px then gives z, and a least-squares
fit (trimmed at 3 sigma, three times) of

    d_measured = a + s fu b / z  [+ c (v - cv)]

returns the bias a. The scale s is free, so poses with a wrong length (a speed error) still give
a; --roll adds the right camera's roll term c (v - cv) of the disparity.
With the ground truth's poses this measures the tracks. With the odometry's own poses it reads
what VO leaves visible of a bias: most of it where the landmarks surround the path, a fifth on
0020's one-sided tracks (docs/disparity_bias.md); scripts/calibrate_disparity_bias.py finds the
bias as the fixed point of VO and this fit.
No dependencies beyond Python.
Usage: disparity_bias.py TRACKS POSES [--min-parallax-deg DEG] [--roll]
"""
import argparse
import collections
import math
import os
import sys


def fail(msg):
    sys.exit(f"disparity_bias.py: {msg}")


def read_numbers(path, count):
    """Rows of COUNT numbers of a whitespace-separated file (blank lines skipped)."""
    rows = []
    try:
        with open(path) as f:
            for line_no, line in enumerate(f, 1):
                if not line.strip():
                    continue
                fields = line.split()
                if len(fields) < count:
                    fail(f"{path}:{line_no}: expected {count} numbers, got {len(fields)}")
                try:
                    rows.append([float(x) for x in fields[:count]])
                except ValueError:
                    fail(f"{path}:{line_no}: not a number")
    except OSError as e:
        fail(f"{path}: {e.strerror}")
    return rows


def read_tracks(path, frames):
    """Observations (frame, uL, vL, uR) per landmark."""
    by_landmark = collections.defaultdict(list)
    try:
        with open(path) as f:
            for line_no, line in enumerate(f, 1):
                fields = line.split(",")
                if line_no == 1 and not fields[0].strip().isdigit():
                    continue  # the header
                if len(fields) < 6:
                    fail(f"{path}:{line_no}: expected frame,landmark,uL,vL,uR,vR")
                try:
                    k, lm = int(fields[0]), int(fields[1])
                    u_l, v_l, u_r = float(fields[2]), float(fields[3]), float(fields[4])
                except ValueError:
                    fail(f"{path}:{line_no}: a field is not a number")
                if k < frames:
                    by_landmark[lm].append((k, u_l, v_l, u_r))
    except OSError as e:
        fail(f"{path}: {e.strerror}")
    return by_landmark


def solve(a, y):
    """Solves the small dense system a x = y by Gauss-Jordan with partial pivoting; None if singular."""
    n = len(y)
    m = [a[i][:] + [y[i]] for i in range(n)]
    for c in range(n):
        p = max(range(c, n), key=lambda r: abs(m[r][c]))
        m[c], m[p] = m[p], m[c]
        if abs(m[c][c]) < 1e-12:
            return None
        for r in range(n):
            if r != c:
                f = m[r][c] / m[c][c]
                for j in range(c, n + 1):
                    m[r][j] -= f * m[c][j]
    return [m[i][n] / m[i][i] for i in range(n)]


def observations(by_landmark, poses, calib, min_parallax_deg):
    """(fu b / z, measured disparity, v - cv) of every observation of a well-triangulated landmark."""
    fu, fv, cu, cv, base = calib
    out = []
    for obs in by_landmark.values():
        if len(obs) < 3:
            continue
        normal = [[0.0] * 3 for _ in range(3)]
        rhs = [0.0] * 3
        rays = []
        for k, u_l, v_l, _ in obs:
            rot, t = poses[k]
            ray_c = [(u_l - cu) / fu, (v_l - cv) / fv, 1.0]
            ray = [sum(rot[i][j] * ray_c[j] for j in range(3)) for i in range(3)]
            norm = math.sqrt(sum(x * x for x in ray))
            ray = [x / norm for x in ray]
            rays.append(ray)
            for i in range(3):  # sum of (I - r r^T) X = sum of (I - r r^T) c
                for j in range(3):
                    m = (1.0 if i == j else 0.0) - ray[i] * ray[j]
                    normal[i][j] += m
                    rhs[i] += m * t[j]
        cos = sum(rays[0][i] * rays[-1][i] for i in range(3))
        if math.degrees(math.acos(max(-1.0, min(1.0, cos)))) < min_parallax_deg:
            continue
        x_w = solve(normal, rhs)
        if x_w is None:
            continue
        rows = []
        for k, u_l, v_l, u_r in obs:
            rot, t = poses[k]
            d = [x_w[i] - t[i] for i in range(3)]
            x_c = [sum(rot[j][i] * d[j] for j in range(3)) for i in range(3)]
            if x_c[2] < 1.0:
                break
            if math.hypot(fu * x_c[0] / x_c[2] + cu - u_l, fv * x_c[1] / x_c[2] + cv - v_l) > 1.0:
                break
            rows.append((fu * base / x_c[2], u_l - u_r, v_l - cv))
        else:
            out.extend(rows)
    return out


def fit(rows, roll):
    """Least squares of d = a + s fu b / z [+ c (v - cv)], trimmed at 3 sigma three times."""
    n = 3 if roll else 2
    for trim in range(4):  # a fit, then three times: trim, fit again
        if trim > 0:
            rows = [row for row, r in zip(rows, res) if abs(r) < 3.0 * sd]
        normal = [[0.0] * n for _ in range(n)]
        rhs = [0.0] * n
        for d_z, d_m, dv in rows:
            x = [1.0, d_z, dv][:n]
            for i in range(n):
                rhs[i] += x[i] * d_m
                for j in range(n):
                    normal[i][j] += x[i] * x[j]
        params = solve(normal, rhs)
        if params is None:
            fail("the fit is singular: too few landmarks, or all at one depth")
        res = [d_m - (params[0] + params[1] * d_z + (params[2] * dv if roll else 0.0))
               for d_z, d_m, dv in rows]
        sd = math.sqrt(sum(r * r for r in res) / len(res))
    # standard error of the bias: sd * sqrt((X^T X)^-1 [0][0]), from the last fit's normal matrix
    inv0 = solve(normal, [1.0] + [0.0] * (n - 1))
    se = sd * math.sqrt(max(inv0[0], 0.0)) if inv0 else float("inf")
    return params, sd, len(rows), se  # the last fit, its residual std, the rows it used, se of a


def read_calib(tracks):
    """(fu, fv, cu, cv, baseline) of TRACKS/calib.txt."""
    path = os.path.join(tracks, "calib.txt")
    rows = read_numbers(path, 5)
    if not rows:
        fail(f"{path}: empty")
    return rows[0]


def read_poses(path):
    """(rotation rows, translation) of every line of a KITTI pose file T_w_c."""
    return [([p[0:3], p[4:7], p[8:11]], [p[3], p[7], p[11]]) for p in read_numbers(path, 12)]


class NothingToFit(Exception):
    """Too few landmarks consistent with the poses for a fit."""


def measure(by_landmark, calib, poses, min_parallax_deg=3.0, roll=False, where="tracks"):
    """The fit of d = a + s fu b / z [+ c (v - cv)] for the landmarks BY_LANDMARK under POSES:
    (params, residual std, observations used, standard error of a). Raises NothingToFit."""
    rows = observations(by_landmark, poses, calib, min_parallax_deg)
    if len(rows) < 10:
        raise NothingToFit(f"{where}: only {len(rows)} observations of landmarks seen over "
                           f"{min_parallax_deg} deg; nothing to fit")
    return fit(rows, roll)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("tracks", help="track folder (tracks.csv, calib.txt)")
    ap.add_argument("poses", help="KITTI pose file T_w_c of the same frames (truth or estimate)")
    ap.add_argument("--min-parallax-deg", type=float, default=3.0,
                    help="a landmark's smallest angle between its first and last ray, deg")
    ap.add_argument("--roll", action="store_true", help="fit the roll term c (v - cv) as well")
    a = ap.parse_args()
    calib = read_calib(a.tracks)
    poses = read_poses(a.poses)
    by_landmark = read_tracks(os.path.join(a.tracks, "tracks.csv"), len(poses))
    try:
        params, sd, used, se = measure(by_landmark, calib, poses, a.min_parallax_deg, a.roll,
                                       a.tracks)
    except NothingToFit as e:
        fail(str(e))
    roll = f"  roll term {params[2]:+.3e} px/px" if a.roll else ""
    print(f"disparity bias {params[0]:+.3f} px (se {se:.3f})  scale {params[1]:.4f}{roll}  "
          f"({used} observations, residual std {sd:.3f} px)")


if __name__ == "__main__":
    main()
