#!/usr/bin/env python3
"""Tests of scripts/pose_error_split.py on small pose files written here."""
import math
import os
import subprocess
import sys
import tempfile
import unittest

import script_test

SCRIPT = None


def write_poses(path, poses):
    with open(path, "w") as f:
        for r, t in poses:
            f.write(" ".join(f"{r[i][0]:.12g} {r[i][1]:.12g} {r[i][2]:.12g} {t[i]:.12g}"
                             for i in range(3)) + "\n")


def roll(angle):  # about the camera's z axis
    c, s = math.cos(angle), math.sin(angle)
    return [[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]


class PoseErrorSplit(unittest.TestCase):
    def run_script(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)

    def test_height_offset_and_roll_are_told_apart(self):
        with tempfile.TemporaryDirectory() as d:
            gt = [(roll(0.0), [0.0, 0.0, float(k)]) for k in range(10)]
            # 0.5 m lower (world up = -y, so +y is down) and rolled by 2 deg.
            run = [(roll(math.radians(-2.0)), [0.0, 0.5, float(k)]) for k in range(10)]
            write_poses(os.path.join(d, "gt.txt"), gt)
            write_poses(os.path.join(d, "run.txt"), run)
            out = self.run_script(os.path.join(d, "gt.txt"), os.path.join(d, "run.txt"))
            self.assertEqual(out.returncode, 0, out.stderr)
            self.assertIn("height error RMS 0.50 m, final -0.50 m", out.stdout)
            self.assertIn("horizontal RMS 0.00 m", out.stdout)
            self.assertIn("tilt RMS 2.00 deg, heading RMS 0.00 deg", out.stdout)
            self.assertIn("roll (z) +2.000 deg", out.stdout)

    def test_a_malformed_line_names_file_and_line(self):
        with tempfile.TemporaryDirectory() as d:
            write_poses(os.path.join(d, "gt.txt"), [(roll(0.0), [0.0, 0.0, 0.0])] * 3)
            with open(os.path.join(d, "bad.txt"), "w") as f:
                f.write("1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0\n1 0 0 0 0 1 0 0 0 0 1 0\n")
            out = self.run_script(os.path.join(d, "gt.txt"), os.path.join(d, "bad.txt"))
            self.assertNotEqual(out.returncode, 0)
            self.assertIn("bad.txt:2: expected 12 numbers, got 3", out.stderr)


if __name__ == "__main__":
    script_test.main(sys.modules[__name__])
