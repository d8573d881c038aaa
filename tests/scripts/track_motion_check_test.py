#!/usr/bin/env python3
"""Tests of scripts/track_motion_check.py on a small track folder written here."""
import math
import os
import random
import re
import subprocess
import sys
import tempfile
import unittest

import script_test

SCRIPT = None
FU, CU, CV, BASE = 700.0, 600.0, 180.0, 0.5


def pitch(angle):  # about the camera's x axis
    c, s = math.cos(angle), math.sin(angle)
    return [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]


def write_folder(d, cv_written, frames=12, vo_tilt=0.0):
    """A camera driving 1 m per frame along z, pitching 0.1 deg per frame, through landmarks 6-80
    m ahead above and below the horizon; images made with the principal row CV, calib.txt written
    with cv_written. With vo_tilt an estimate whose translation is turned by vo_tilt rad about x."""
    poses = []
    for k in range(frames):
        poses.append((pitch(math.radians(0.1 * k)), [0.0, 0.0, float(k)]))
    rng = random.Random(3)
    points = [(rng.uniform(-20, 20), rng.choice((-1, 1)) * rng.uniform(1, 6), rng.uniform(6, 80) + frames)
              for _ in range(300)]
    with open(os.path.join(d, "calib.txt"), "w") as f:
        f.write(f"{FU} {FU} {CU} {cv_written} {BASE}\n")
    with open(os.path.join(d, "tracks.csv"), "w") as f:
        f.write("frame,landmark,uL,vL,uR,vR\n")
        for k, (r, t) in enumerate(poses):
            for j, p in enumerate(points):
                d_w = [p[i] - t[i] for i in range(3)]
                x, y, z = (sum(r[i][m] * d_w[i] for i in range(3)) for m in range(3))
                if z < 2.0:
                    continue
                u, v = CU + FU * x / z, CV + FU * y / z
                f.write(f"{k},{j},{u:.6f},{v:.6f},{u - FU * BASE / z:.6f},{v:.6f}\n")
    for name, tilt in (("gt_poses.txt", 0.0), ("vo.txt", vo_tilt)):
        with open(os.path.join(d, name), "w") as f:
            for r, t in poses:
                c, s = math.cos(tilt), math.sin(tilt)
                tt = [t[0], c * t[1] - s * t[2], s * t[1] + c * t[2]]
                f.write(" ".join(f"{r[i][0]:.12g} {r[i][1]:.12g} {r[i][2]:.12g} {tt[i]:.12g}"
                                 for i in range(3)) + "\n")


def medians(stdout, span):
    line = next(l for l in stdout.splitlines() if l.strip().startswith(span))
    return [float(x) for x in re.findall(r"([+-]\d+\.\d+) \(n", line)]


class TrackMotionCheck(unittest.TestCase):
    def run_script(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)

    def test_exact_tracks_leave_no_residual_and_the_same_translation(self):
        with tempfile.TemporaryDirectory() as d:
            write_folder(d, CV)
            out = self.run_script(d, "--vo", os.path.join(d, "vo.txt"))
            self.assertEqual(out.returncode, 0, out.stderr)
            for value in medians(out.stdout, "5-10 m") + medians(out.stdout, "30-60 m"):
                self.assertAlmostEqual(value, 0.0, places=3)
            self.assertIn("estimate - truth +0.00 mrad", out.stdout)

    def test_a_principal_row_error_shows_as_one_sign_above_and_below(self):
        with tempfile.TemporaryDirectory() as d:
            write_folder(d, CV - 3.0, vo_tilt=0.004)
            out = self.run_script(d, "--vo", os.path.join(d, "vo.txt"))
            self.assertEqual(out.returncode, 0, out.stderr)
            near, far = medians(out.stdout, "5-10 m"), medians(out.stdout, "30-60 m")
            # 3 px of row error reads as -3 px * 1 m / z: both sides negative, near larger.
            for value in near:
                self.assertLess(value, -0.2)
            self.assertLess(near[0], 3.0 * far[0])
            self.assertIn("estimate - truth -4.00 mrad", out.stdout)

    def test_under_the_motion_that_explains_the_rows_none_is_left(self):
        with tempfile.TemporaryDirectory() as d:
            # The 3 px row error read as a translation tilted by 3 / FU rad: the estimate's
            # vertical step differs from the truth's by -3 / FU m per metre.
            write_folder(d, CV - 3.0, vo_tilt=-3.0 / FU)
            vo = os.path.join(d, "vo.txt")
            out = self.run_script(d, "--vo", vo, "--under", vo)
            self.assertEqual(out.returncode, 0, out.stderr)
            self.assertIn(f"under the motion of {vo}", out.stdout)
            for value in medians(out.stdout, "5-10 m") + medians(out.stdout, "15-20 m"):
                self.assertAlmostEqual(value, 0.0, delta=0.02)
            self.assertIn("vertical translation t_y -4.29 (-4.29) mm", out.stdout)

    def test_a_malformed_line_names_file_and_line(self):
        with tempfile.TemporaryDirectory() as d:
            write_folder(d, CV)
            with open(os.path.join(d, "tracks.csv"), "a") as f:
                f.write("3,7,1.0,2.0\n")
            out = self.run_script(d)
            self.assertNotEqual(out.returncode, 0)
            self.assertRegex(out.stderr, r"tracks\.csv:\d+: expected 6 numbers, got 4")


if __name__ == "__main__":
    script_test.main(sys.modules[__name__])
