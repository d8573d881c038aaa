#!/usr/bin/env python3
"""Tests of scripts/pixel_locking.py on small track folders written here."""
import os
import random
import subprocess
import sys
import tempfile
import unittest

import script_test

SCRIPT = None


def write_tracks(folder, rows):
    with open(os.path.join(folder, "tracks.csv"), "w") as f:
        f.write("frame,landmark,uL,vL,uR,vR\n")
        for k, (uL, vL, uR, vR) in enumerate(rows):
            f.write(f"{k // 10},{k},{uL:.3f},{vL:.3f},{uR:.3f},{vR:.3f}\n")


class PixelLocking(unittest.TestCase):
    def run_script(self, folder):
        return subprocess.run([sys.executable, SCRIPT, folder], capture_output=True, text=True)

    def test_locked_and_uniform_measurements_are_told_apart(self):
        rng = random.Random(7)
        rows = []
        for _ in range(2000):
            uL = rng.uniform(10.0, 600.0)
            vL = rng.uniform(10.0, 300.0)
            # The disparity is locked to whole pixels, the row offset is uniform.
            uR = uL - rng.randint(2, 40)
            vR = vL - rng.uniform(-1.0, 1.0)
            rows.append((uL, vL, uR, vR))
        with tempfile.TemporaryDirectory() as d:
            write_tracks(d, rows)
            out = self.run_script(d)
            self.assertEqual(out.returncode, 0, out.stderr)
            lines = {line.split("  ")[0].strip(): line for line in out.stdout.splitlines()[1:]}
            self.assertIn("within 0.01 px of a whole pixel 100.00 %", lines["uL - uR"])
            share = float(lines["vL - vR"].split("whole pixel")[1].split("%")[0])
            self.assertGreater(share, 0.5)
            self.assertLess(share, 4.0)

    def test_a_malformed_line_names_file_and_line(self):
        with tempfile.TemporaryDirectory() as d:
            write_tracks(d, [(10.0, 10.0, 5.0, 10.0)])
            with open(os.path.join(d, "tracks.csv"), "a") as f:
                f.write("1,2,3.0,x,1.0,2.0\n")
            out = self.run_script(d)
            self.assertNotEqual(out.returncode, 0)
            self.assertIn("tracks.csv:3: expected four numbers in uL,vL,uR,vR", out.stderr)


if __name__ == "__main__":
    script_test.main(sys.modules[__name__])
