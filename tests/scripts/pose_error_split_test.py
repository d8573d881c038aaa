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


def pitch(angle):  # about the camera's x axis
    c, s = math.cos(angle), math.sin(angle)
    return [[1.0, 0.0, 0.0], [0.0, c, -s], [0.0, s, c]]


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

    def test_a_pitched_run_builds_its_height_from_the_tilt(self):
        # 10 true steps of 1 m along z; the run's attitude pitched by 1 deg (C_w,gt = Exp(w)
        # C_w,run, w = 1 deg about x) walks each step turned by it: 10 sin(1 deg) m lower.
        a = math.radians(1.0)
        with tempfile.TemporaryDirectory() as d:
            gt = [(roll(0.0), [0.0, 0.0, float(k)]) for k in range(11)]
            run = [(pitch(-a), [0.0, k * math.sin(a), k * math.cos(a)]) for k in range(11)]
            write_poses(os.path.join(d, "gt.txt"), gt)
            write_poses(os.path.join(d, "run.txt"), run)
            write_poses(os.path.join(d, "same.txt"), gt)
            out = self.run_script(os.path.join(d, "gt.txt"), os.path.join(d, "run.txt"),
                                  os.path.join(d, "same.txt"), "--cue-sigma-deg", "1",
                                  "--answers", "4")
            self.assertEqual(out.returncode, 0, out.stderr)
            lines = out.stdout.splitlines()
            self.assertEqual(len(lines), 3, out.stdout)
            # 1 deg x 10 m / sqrt(4)
            self.assertIn("route 10.0 m; the cue's height floor 1 deg x 10.0 m / sqrt(4) = 0.09 m",
                          lines[0])
            self.assertIn("final -0.17 m", lines[1])
            self.assertIn("pitch (x) +1.000 deg", lines[1])
            self.assertIn("height built by the tilt -0.17 m", lines[1])
            self.assertIn("height built by the tilt +0.00 m", lines[2])

    def test_the_floor_needs_both_its_numbers(self):
        with tempfile.TemporaryDirectory() as d:
            write_poses(os.path.join(d, "gt.txt"), [(roll(0.0), [0.0, 0.0, 0.0])] * 3)
            out = self.run_script(os.path.join(d, "gt.txt"), os.path.join(d, "gt.txt"),
                                  "--answers", "4")
            self.assertNotEqual(out.returncode, 0)
            self.assertIn("--cue-sigma-deg and --answers go together", out.stderr)

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
