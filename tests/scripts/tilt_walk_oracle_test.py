#!/usr/bin/env python3
"""Tests of scripts/tilt_walk_oracle.py on small pose files written here."""
import math
import os
import random
import subprocess
import sys
import tempfile
import unittest

import script_test
from pose_error_split_test import pitch, roll, write_poses

SCRIPT = None


class TiltWalkOracle(unittest.TestCase):
    def run_script(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)

    def test_a_drift_in_pitch_alone_is_followed_better_per_axis(self):
        # A straight drive along z: the camera's x is the world's x, its z the world's z. The run's
        # attitude walks 0.05 deg/frame in pitch and not at all in roll, so one walk for both axes
        # lets the cue's noise into the roll, which a walk per axis keeps out.
        rng = random.Random(3)
        angle, gt, run = 0.0, [], []
        for k in range(300):
            angle += rng.gauss(0.0, math.radians(0.05))
            gt.append((roll(0.0), [0.0, 0.0, float(k)]))
            run.append((pitch(-angle), [0.0, 0.0, float(k)]))
        with tempfile.TemporaryDirectory() as d:
            write_poses(os.path.join(d, "gt.txt"), gt)
            write_poses(os.path.join(d, "run.txt"), run)
            out = self.run_script(os.path.join(d, "gt.txt"), os.path.join(d, "run.txt"),
                                  "--walks-deg", "0.0055,0.05", "--draws", "6")
            self.assertEqual(out.returncode, 0, out.stderr)
            best = {}
            for line in out.stdout.splitlines():
                if line.startswith("best "):
                    kind = line.split(":")[0][len("best "):]
                    best[kind] = (line.split(": ")[1].split(" deg/frame")[0],
                                  float(line.split("tilt RMS ")[1].split(" deg")[0]))
            self.assertEqual(best["per axis"][0], "0.0500 / 0.0055", out.stdout)
            self.assertEqual(best["one walk"][0], "0.0500", out.stdout)
            self.assertLess(best["per axis"][1], best["one walk"][1], out.stdout)

    def test_a_run_without_error_has_nothing_to_follow(self):
        gt = [(roll(0.0), [0.0, 0.0, float(k)]) for k in range(20)]
        with tempfile.TemporaryDirectory() as d:
            write_poses(os.path.join(d, "gt.txt"), gt)
            out = self.run_script(os.path.join(d, "gt.txt"), os.path.join(d, "gt.txt"),
                                  "--walks-deg", "0.01", "--draws", "2")
            self.assertEqual(out.returncode, 0, out.stderr)
            self.assertIn("pure VO tilt RMS 0.000 deg, height built by the tilt +0.00 m",
                          out.stdout)

    def test_bad_input_is_named(self):
        with tempfile.TemporaryDirectory() as d:
            write_poses(os.path.join(d, "gt.txt"), [(roll(0.0), [0.0, 0.0, 0.0])] * 3)
            write_poses(os.path.join(d, "short.txt"), [(roll(0.0), [0.0, 0.0, 0.0])] * 2)
            out = self.run_script(os.path.join(d, "gt.txt"), os.path.join(d, "short.txt"))
            self.assertNotEqual(out.returncode, 0)
            self.assertIn("short.txt: 2 poses, the ground truth has 3", out.stderr)
            out = self.run_script(os.path.join(d, "gt.txt"), os.path.join(d, "gt.txt"),
                                  "--walks-deg", "0.01,x")
            self.assertNotEqual(out.returncode, 0)
            self.assertIn("--walks-deg: not a list of numbers", out.stderr)


if __name__ == "__main__":
    script_test.main(sys.modules[__name__])
