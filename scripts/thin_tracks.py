#!/usr/bin/env python3
"""A track folder with a share of its landmarks left out: a sparser real route (issue 15).

Real track folders of other routes are sparser than 0020's 64 tracks per frame, and VO's failure
modes there (frames with a handful of tracks, one-sided tracks, runs of lost frames) are what a
new route meets first. Reads TRACKS (a track folder: tracks.csv, calib.txt, times.txt and, when
present, gt_poses.txt and sun_cam.csv), keeps each landmark with probability KEEP, drawn once per
landmark from SEED (a kept landmark keeps every observation, so the track lengths stay real), and
writes OUT with the other files copied. `sunvo_track_vo OUT out.txt` and `sunvo_experiment
--routes OUT` then run on it (docs/sparse_tracks.md).
No dependencies beyond Python. Usage: thin_tracks.py TRACKS OUT --keep KEEP [--seed SEED]
"""
import argparse
import os
import random
import shutil
import sys

COPIED = ("calib.txt", "times.txt", "gt_poses.txt", "sun_cam.csv")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("tracks", help="track folder")
    ap.add_argument("out", help="output folder (created)")
    ap.add_argument("--keep", type=float, required=True, help="share of landmarks kept, (0, 1]")
    ap.add_argument("--seed", type=int, default=1, help="seed of the draw")
    a = ap.parse_args()
    if not 0.0 < a.keep <= 1.0:
        sys.exit(f"thin_tracks.py: --keep {a.keep}: must be in (0, 1]")
    src = os.path.join(a.tracks, "tracks.csv")
    if not os.path.isfile(src):
        sys.exit(f"thin_tracks.py: {src}: no such file")
    os.makedirs(a.out, exist_ok=True)
    for name in COPIED:
        if os.path.isfile(os.path.join(a.tracks, name)):
            shutil.copy(os.path.join(a.tracks, name), a.out)
    rng = random.Random(a.seed)
    kept = {}
    n_in = n_out = 0
    with open(src) as fi, open(os.path.join(a.out, "tracks.csv"), "w") as fo:
        for line_no, line in enumerate(fi, 1):
            fields = line.split(",")
            if line_no == 1 and not fields[0].strip().isdigit():
                fo.write(line)  # the header
                continue
            if len(fields) < 6:
                sys.exit(f"thin_tracks.py: {src}:{line_no}: expected frame,landmark,uL,vL,uR,vR")
            landmark = fields[1].strip()
            if landmark not in kept:
                kept[landmark] = rng.random() < a.keep
            n_in += 1
            if kept[landmark]:
                fo.write(line)
                n_out += 1
    n_kept = sum(kept.values())
    print(f"{a.out}: {n_kept} of {len(kept)} landmarks, {n_out} of {n_in} observations")


if __name__ == "__main__":
    main()
