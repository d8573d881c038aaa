#!/usr/bin/env python3
"""A track folder with frames left out, numbered on without a gap: a camera that drops frames,
or a stretch of a route as a route of its own.

KITTI raw and odometry data number their frames consecutively; where the recorder lost a frame
only the timestamp jumps. A camera driver that loses a buffer under load does the same to a
rover's log. This makes such a folder from a real one (docs/motion_prior.md, "Dropped frames"):
each frame after the first is left out with probability DROP drawn from SEED, or every N-th frame
with --every N. tracks.csv, times.txt, gt_poses.txt and sun_cam.csv keep the rows of the kept
frames and are numbered 0, 1, 2, ... again; calib.txt is copied.
--range FIRST COUNT keeps frames FIRST .. FIRST+COUNT-1 only: a short route that starts anywhere
(in a turn, with the rig's error already there; docs/sparse_tracks.md, "Short routes"). Its ground
truth is re-expressed in the first kept frame's camera (T_0_k = T_w_first^-1 T_w_k), so it starts
at the identity like any KITTI pose file.
No dependencies beyond Python.
Usage: drop_frames.py TRACKS OUT (--drop DROP [--seed SEED] | --every N | --range FIRST COUNT)
"""
import argparse
import os
import random
import shutil
import sys


def fail(msg):
    sys.exit(f"drop_frames.py: {msg}")


def read_lines(path):
    with open(path) as f:
        return [line for line in f.read().splitlines() if line.strip()]


def renumber_csv(src, dst, new_index, what):
    """Keeps the rows whose first field is a kept frame, renumbered; keeps a header line."""
    lines = read_lines(src)
    with open(dst, "w") as out:
        for line_no, line in enumerate(lines, 1):
            frame, sep, rest = line.partition(",")
            if line_no == 1 and not frame.strip().isdigit():
                out.write(line + "\n")
                continue
            if not sep or not frame.strip().isdigit():
                fail(f"{src}:{line_no}: field 'frame': expected a frame number, then {what}")
            k = int(frame)
            if k >= len(new_index):
                fail(f"{src}:{line_no}: field 'frame': {k} is past the {len(new_index)} frames "
                     "of times.txt")
            if new_index[k] is not None:
                out.write(f"{new_index[k]},{rest}\n")


def relative_pose(first, pose, where):
    """T_first^-1 T for 3x4 row-major KITTI poses (12 numbers each), as a pose line."""
    try:
        a, b = [float(x) for x in first.split()], [float(x) for x in pose.split()]
    except ValueError:
        fail(f"{where}: not a number")
    if len(a) != 12 or len(b) != 12:
        fail(f"{where}: expected 12 numbers")
    out = []
    for i in range(3):
        for j in range(3):  # (R_first^T R)_ij
            out.append(sum(a[4 * k + i] * b[4 * k + j] for k in range(3)))
        out.append(sum(a[4 * k + i] * (b[4 * k + 3] - a[4 * k + 3]) for k in range(3)))
    return " ".join(f"{x:.9e}" for x in out)


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("tracks", help="track folder")
    ap.add_argument("out", help="output folder (created)")
    how = ap.add_mutually_exclusive_group(required=True)
    how.add_argument("--drop", type=float, help="share of frames left out, [0, 1)")
    how.add_argument("--every", type=int, help="leave out every N-th frame, N >= 2")
    how.add_argument("--range", type=int, nargs=2, metavar=("FIRST", "COUNT"),
                     help="keep frames FIRST .. FIRST+COUNT-1 only, COUNT >= 2")
    ap.add_argument("--seed", type=int, default=1, help="seed of the draw (with --drop)")
    a = ap.parse_args()
    if a.drop is not None and not 0.0 <= a.drop < 1.0:
        fail(f"--drop {a.drop}: must be in [0, 1)")
    if a.every is not None and a.every < 2:
        fail(f"--every {a.every}: must be >= 2")
    times_path = os.path.join(a.tracks, "times.txt")
    for name in ("tracks.csv", "times.txt"):
        if not os.path.isfile(os.path.join(a.tracks, name)):
            fail(f"{os.path.join(a.tracks, name)}: no such file")
    times = read_lines(times_path)
    n = len(times)
    rng = random.Random(a.seed)
    if a.range is not None:
        first, count = a.range
        if first < 0 or count < 2 or first + count > n:
            fail(f"--range {first} {count}: outside the {n} frames of {times_path}")
        keep = [first <= k < first + count for k in range(n)]
    elif a.every is not None:
        keep = [k == 0 or (k + 1) % a.every != 0 for k in range(n)]
    else:
        keep = [k == 0 or rng.random() >= a.drop for k in range(n)]
    new_index, kept = [], 0
    for k in range(n):
        new_index.append(kept if keep[k] else None)
        kept += keep[k]
    os.makedirs(a.out, exist_ok=True)
    shutil.copy(os.path.join(a.tracks, "calib.txt"), a.out)
    with open(os.path.join(a.out, "times.txt"), "w") as f:
        f.writelines(t + "\n" for t, k in zip(times, keep) if k)
    gt = os.path.join(a.tracks, "gt_poses.txt")
    if os.path.isfile(gt):
        poses = read_lines(gt)
        if len(poses) != n:
            fail(f"{gt}: {len(poses)} poses, but times.txt has {n} frames")
        kept_poses = [p for p, k in zip(poses, keep) if k]
        if not keep[0]:  # a stretch: the first kept frame becomes the origin
            first_line = keep.index(True) + 1
            kept_poses = [relative_pose(kept_poses[0], p, f"{gt}:{first_line + i}")
                          for i, p in enumerate(kept_poses)]
        with open(os.path.join(a.out, "gt_poses.txt"), "w") as f:
            f.writelines(p + "\n" for p in kept_poses)
    renumber_csv(os.path.join(a.tracks, "tracks.csv"), os.path.join(a.out, "tracks.csv"),
                 new_index, "landmark,uL,vL,uR,vR")
    sun = os.path.join(a.tracks, "sun_cam.csv")
    if os.path.isfile(sun):
        renumber_csv(sun, os.path.join(a.out, "sun_cam.csv"), new_index, "sx,sy,sz")
    print(f"{a.out}: {kept} of {n} frames kept")


if __name__ == "__main__":
    main()
