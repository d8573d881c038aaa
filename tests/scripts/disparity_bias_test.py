#!/usr/bin/env python3
"""Tests of scripts/disparity_bias.py on a simulated forward drive: a known disparity bias is
recovered from the true poses, the same with poses of the wrong length (the scale is free), the
right camera's roll term with --roll, an unbiased rig reads 0, and bad input names the file."""
import os
import random
import re
import subprocess
import sys
import tempfile
import unittest

import script_test

SCRIPT = None
FU, CU, CV, BASE = 700.0, 620.0, 187.0, 0.5
FRAMES = 40


def write_drive(folder, bias_px, roll_px_per_px=0.0, pose_scale=1.0, seed=3):
    """A camera driving 1 m per frame along z past 400 landmarks; disparities carry bias_px +
    roll_px_per_px (v - cv) and 0.05 px of noise; gt_poses.txt is scaled by pose_scale."""
    rng = random.Random(seed)
    os.makedirs(folder)
    lines = ["frame,landmark,uL,vL,uR,vR"]
    for lm in range(400):
        x, y, z = rng.uniform(-20, 20), rng.uniform(-4, 2), rng.uniform(10, 70)
        for k in range(FRAMES):
            zc = z - k
            if zc < 4.0:
                break
            u, v = FU * x / zc + CU, FU * y / zc + CV
            if not (0 <= u < 1242 and 0 <= v < 375):
                continue
            d = FU * BASE / zc + bias_px + roll_px_per_px * (v - CV) + rng.gauss(0, 0.05)
            lines.append(f"{k},{lm},{u:.4f},{v:.4f},{u - d:.4f},{v:.4f}")
    files = {
        "tracks.csv": "\n".join(lines) + "\n",
        "calib.txt": f"{FU} {FU} {CU} {CV} {BASE}\n",
        "gt_poses.txt": "".join(f"1 0 0 0 0 1 0 0 0 0 1 {pose_scale * k}\n" for k in range(FRAMES)),
    }
    for name, text in files.items():
        with open(os.path.join(folder, name), "w") as f:
            f.write(text)


class DisparityBias(unittest.TestCase):
    def run_script(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)

    def measure(self, folder, *extra):
        r = self.run_script(folder, os.path.join(folder, "gt_poses.txt"), *extra)
        self.assertEqual(r.returncode, 0, r.stderr)
        m = re.search(r"disparity bias ([-+.\d]+) px \(se ([.\d]+)\)\s+scale ([-+.\d]+)", r.stdout)
        self.assertIsNotNone(m, r.stdout)
        self.assertLess(float(m.group(2)), 0.02, r.stdout)  # 0.05 px noise: a well-defined fit
        roll = re.search(r"roll term ([-+.\de]+)", r.stdout)
        return float(m.group(1)), float(m.group(3)), float(roll.group(1)) if roll else None

    def test_recovers_the_bias_with_a_free_scale(self):
        with tempfile.TemporaryDirectory() as d:
            for name, bias, scale in (("a", -0.4, 1.0), ("b", -0.4, 1.05), ("c", 0.0, 1.0)):
                folder = os.path.join(d, name)
                write_drive(folder, bias, pose_scale=scale)
                got, s, _ = self.measure(folder)
                self.assertAlmostEqual(got, bias, delta=0.03, msg=name)
                self.assertAlmostEqual(s, scale, delta=0.01, msg=name)  # z grows with the poses

    def test_roll_term(self):
        with tempfile.TemporaryDirectory() as d:
            folder = os.path.join(d, "r")
            write_drive(folder, -0.2, roll_px_per_px=1.5e-3)
            bias, _, roll = self.measure(folder, "--roll")
            self.assertAlmostEqual(bias, -0.2, delta=0.03)
            self.assertAlmostEqual(roll, 1.5e-3, delta=0.2e-3)

    def test_bad_input_names_the_file(self):
        with tempfile.TemporaryDirectory() as d:
            folder = os.path.join(d, "a")
            write_drive(folder, 0.0)
            r = self.run_script(folder, os.path.join(d, "missing.txt"))
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("missing.txt", r.stderr)
            with open(os.path.join(folder, "gt_poses.txt"), "a") as f:
                f.write("1 0 0 0 0 1 0 0 0 0 x 1\n")
            r = self.run_script(folder, os.path.join(folder, "gt_poses.txt"))
            self.assertNotEqual(r.returncode, 0)
            self.assertIn(f"gt_poses.txt:{FRAMES + 1}: not a number", r.stderr)


if __name__ == "__main__":
    script_test.main(sys.modules[__name__])
