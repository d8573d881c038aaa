#!/usr/bin/env python3
"""A rig's constant disparity bias from a drive's own tracks: the fixed point of VO and the fit.

scripts/disparity_bias.py measures the bias a of d = a + s fu b / z against a set of poses. With
the odometry's own poses VO absorbs most of a bias (on 0020 it leaves about a fifth of it visible,
docs/disparity_bias.md), so one reading is not the bias. But the reading r(A) of poses that VO
computed with a bias A entered (--disparity-bias-px A, taken out of every right column) equals A
only where A is the bias: the poses of a rig whose disparities are right give a fit with no
intercept left. So the bias is the root of

    g(A) = r(A) - A,

found here without any ground truth: g on a grid of A (a sunvo_track_vo run and a fit each), then
a least-squares line through five runs around each place where g changes sign from + to -, whose
root is the bias. The line's slope -g' is the share of a bias that VO leaves visible; under
--min-slope the bias is not observable enough from this drive (the landmarks do not surround the
path, docs/disparity_bias.md) and the script refuses it, as it does a root whose se exceeds
--max-se.
With --self-calib among the VO options the right camera's roll is taken out by VO, and the fit
models it (the roll term c (v - cv)); without it the fit returns the constant that best stands
for both.
Usage: calibrate_disparity_bias.py TRACKS [--track-vo BIN] [--range LO HI] [--step S] [--local W]
                                   [--work DIR] [-- VO OPTIONS]
"""
import argparse
import math
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import disparity_bias  # noqa: E402  (the fit; same folder)


def fail(msg, code=1):
    print(f"calibrate_disparity_bias.py: {msg}", file=sys.stderr)
    sys.exit(code)


def default_track_vo():
    """sunvo_track_vo on PATH, else the release build of this checkout."""
    found = shutil.which("sunvo_track_vo")
    if found:
        return found
    here = os.path.dirname(os.path.abspath(__file__))
    return os.path.join(here, "..", "build", "release", "bin", "sunvo_track_vo")


class Probe:
    """g(A) = r(A) - A: one VO run with A entered and one fit of its poses."""

    def __init__(self, args, vo_args):
        self.args, self.vo_args = args, vo_args
        self.roll = "--self-calib" in vo_args
        self.calib = disparity_bias.read_calib(args.tracks)
        self.by_landmark = disparity_bias.read_tracks(os.path.join(args.tracks, "tracks.csv"),
                                                      10**9)
        self.runs = []  # (A, reading, used, se, VO summary line)

    def __call__(self, bias):
        poses_path = os.path.join(self.args.work, f"vo_{len(self.runs)}.txt")
        cmd = [self.args.track_vo, self.args.tracks, poses_path, *self.vo_args,
               "--disparity-bias-px", f"{bias:.6f}"]
        try:
            r = subprocess.run(cmd, capture_output=True, text=True)
        except OSError as e:
            fail(f"{self.args.track_vo}: {e.strerror}")
        if r.returncode != 0:
            fail(f"{' '.join(cmd)} failed ({r.returncode}): {r.stderr.strip()[-500:]}")
        summary = [ln for ln in r.stdout.splitlines() if ln.startswith("minimal summary")]
        try:
            params, _, used, se = disparity_bias.measure(
                self.by_landmark, self.calib, disparity_bias.read_poses(poses_path),
                self.args.min_parallax_deg, self.roll, self.args.tracks)
        except disparity_bias.NothingToFit:
            print(f"  entered {bias:+.3f} px: no landmark consistent with VO's poses", flush=True)
            return None
        self.runs.append((bias, params[0], used, se, summary[0] if summary else ""))
        print(f"  entered {bias:+.3f} px: reading {params[0]:+.3f} px (se {se:.3f}), "
              f"g {params[0] - bias:+.3f}, {used} observations", flush=True)
        return params[0] - bias


def line_root(points):
    """Root of the least-squares line g = g0 + k (A - mean) through POINTS [(A, g)]: (root, slope
    k, standard error of the root from the residuals)."""
    n = len(points)
    mean = sum(x for x, _ in points) / n
    sxx = sum((x - mean) ** 2 for x, _ in points)
    g_mean = sum(g for _, g in points) / n
    k = sum((x - mean) * (g - g_mean) for x, g in points) / sxx if sxx > 0.0 else 0.0
    if k == 0.0:
        return mean, 0.0, float("inf")
    root = mean - g_mean / k
    res = [g - g_mean - k * (x - mean) for x, g in points]
    sd = math.sqrt(sum(r * r for r in res) / max(n - 2, 1))
    se = sd / abs(k) * math.sqrt(1.0 / n + (root - mean) ** 2 / sxx)
    return root, k, se


def main():
    argv = sys.argv[1:]
    vo_args = []
    if "--" in argv:
        vo_args = argv[argv.index("--") + 1:]
        argv = argv[:argv.index("--")]
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("tracks", help="track folder (tracks.csv, calib.txt, times.txt)")
    ap.add_argument("--track-vo", default=default_track_vo(), help="the sunvo_track_vo program")
    ap.add_argument("--range", nargs=2, type=float, default=(-1.0, 1.0), metavar=("LO", "HI"),
                    help="biases searched, px (default -1 1)")
    ap.add_argument("--step", type=float, default=0.25, help="grid step, px (default 0.25)")
    ap.add_argument("--min-parallax-deg", type=float, default=3.0,
                    help="a landmark's smallest angle between its first and last ray, deg")
    ap.add_argument("--min-slope", type=float, default=0.5,
                    help="smallest share of a bias VO may leave visible (-g' at the root)")
    ap.add_argument("--local", type=float, default=0.4,
                    help="half-width of the five runs around a crossing that the line is fitted to, px")
    ap.add_argument("--max-se", type=float, default=0.05,
                    help="largest standard error of the bias accepted, px")
    ap.add_argument("--work", help="folder for the VO runs' poses (default: a temporary one)")
    args = ap.parse_args(argv)
    lo, hi = args.range
    if not (-5.0 <= lo < hi <= 5.0) or args.step <= 0.0 or args.local <= 0.0:
        fail("--range must lie in [-5, 5] px with LO < HI, --step and --local > 0")
    if "--disparity-bias-px" in vo_args:
        fail("--disparity-bias-px is what this script sets; leave it out of the VO options")
    with tempfile.TemporaryDirectory() as tmp:
        if args.work is None:
            args.work = tmp
        os.makedirs(args.work, exist_ok=True)
        probe = Probe(args, vo_args)
        print(f"grid {lo:+.2f} .. {hi:+.2f} px, step {args.step:.2f}"
              f"{', roll term fitted (VO runs with --self-calib)' if probe.roll else ''}")
        count = max(1, int(round((hi - lo) / args.step)))
        grid = [(x, probe(x)) for x in (lo + i * (hi - lo) / count for i in range(count + 1))]
        brackets = [(a, b) for a, b in zip(grid, grid[1:])
                    if a[1] is not None and b[1] is not None and a[1] > 0 >= b[1]]
        if not brackets:
            fail(f"no bias in [{lo}, {hi}] px where VO's poses and the fit agree; "
                 "widen --range", 3)
        roots = []
        for (a, g_a), (b, g_b) in brackets:  # a line through local points around each crossing
            guess = a - g_a * (b - a) / (g_b - g_a)
            local = [min(5.0, max(-5.0, guess + args.local * i / 2)) for i in range(-2, 3)]
            first = len(probe.runs)
            points = [(x, probe(x)) for x in local]
            points = [(x, g) for x, g in points if g is not None]
            if len(points) < 3:
                continue
            root, k, se = line_root(points)
            used = sum(run[2] for run in probe.runs[first:]) // len(points)
            roots.append((root, -k, se, used))
        if not roots:
            fail("no VO run near the crossing gave a fit", 3)
        best = max(roots, key=lambda root: root[3])  # the most observations consistent with VO
        if len(roots) > 1:
            print("fixed points: " + ", ".join(f"{x:+.3f} px ({u} observations)"
                                              for x, _, _, u in roots))
        x, slope, se, _ = best
        print(f"disparity bias {x:+.3f} px (se {se:.3f})  (VO leaves {100 * slope:.0f} % of a "
              f"bias visible; {len(probe.runs)} VO runs)")
        if slope < args.min_slope:
            fail(f"{args.tracks}: the bias is not observable enough from this drive: VO leaves "
                 f"{100 * slope:.1f} % of a bias visible (--min-slope {args.min_slope}), so a small "
                 f"error of its poses moves the fixed point {1 / max(slope, 1e-3):.0f} times as "
                 "far (landmarks on one side of the path, docs/disparity_bias.md); measure the "
                 "bias against poses of known length (scripts/disparity_bias.py)", 4)
        if se > args.max_se:
            fail(f"{args.tracks}: the bias is not determined to --max-se {args.max_se} px "
                 f"(se {se:.3f} px): use a longer drive", 4)
        if probe(x) is not None and probe.runs[-1][4]:
            print(f"VO at the bias: {probe.runs[-1][4]}")
        print(f"config: self_calibration.disparity_bias_px: {x:.3f}")


if __name__ == "__main__":
    main()
