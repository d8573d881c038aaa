#!/usr/bin/env python3
"""Tests of scripts/thin_tracks.py: whole landmarks are kept or left out, at about the asked
share, the same for the same seed; the other files are copied; bad input names the file."""
import csv
import os
import subprocess
import sys
import tempfile
import unittest

import script_test

SCRIPT = None
LANDMARKS, FRAMES = 400, 5


class ThinTracks(unittest.TestCase):
    def run_script(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)

    def write_folder(self, d):
        os.makedirs(d)
        with open(os.path.join(d, "calib.txt"), "w") as f:
            f.write("700 700 600 180 0.5\n")
        with open(os.path.join(d, "times.txt"), "w") as f:
            f.write("".join(f"{0.1 * k}\n" for k in range(FRAMES)))
        with open(os.path.join(d, "tracks.csv"), "w") as f:
            f.write("frame,landmark,uL,vL,uR,vR\n")
            for k in range(FRAMES):
                for i in range(LANDMARKS):
                    f.write(f"{k},{i},{100 + i},{50 + k},{90 + i},{50 + k}\n")

    def read(self, folder):
        with open(os.path.join(folder, "tracks.csv"), newline="") as f:
            return [(int(r["frame"]), int(r["landmark"])) for r in csv.DictReader(f)]

    def test_keeps_whole_landmarks_at_the_share(self):
        with tempfile.TemporaryDirectory() as d:
            src = os.path.join(d, "src")
            self.write_folder(src)
            out = os.path.join(d, "out")
            r = self.run_script(src, out, "--keep", "0.3", "--seed", "4")
            self.assertEqual(r.returncode, 0, r.stderr)
            rows = self.read(out)
            kept = {lm for _, lm in rows}
            # Binomial(400, 0.3): std 9.2 landmarks; 4 std either side.
            self.assertLess(abs(len(kept) - 0.3 * LANDMARKS), 37)
            for lm in kept:  # every observation of a kept landmark
                self.assertEqual(sum(1 for _, x in rows if x == lm), FRAMES)
            for name in ("calib.txt", "times.txt"):
                self.assertTrue(os.path.isfile(os.path.join(out, name)))
            again, other = os.path.join(d, "again"), os.path.join(d, "other")
            r = self.run_script(src, again, "--keep", "0.3", "--seed", "4")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertEqual(self.read(again), rows)  # the same seed, the same landmarks
            r = self.run_script(src, other, "--keep", "0.3", "--seed", "5")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertNotEqual(self.read(other), rows)

    def test_bad_input_names_the_file(self):
        with tempfile.TemporaryDirectory() as d:
            r = self.run_script(os.path.join(d, "none"), os.path.join(d, "out"), "--keep", "0.5")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("tracks.csv", r.stderr)
            src = os.path.join(d, "src")
            self.write_folder(src)
            r = self.run_script(src, os.path.join(d, "out"), "--keep", "0")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("--keep", r.stderr)
            with open(os.path.join(src, "tracks.csv"), "a") as f:
                f.write("5,3,1.0\n")
            r = self.run_script(src, os.path.join(d, "out2"), "--keep", "1")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("tracks.csv:" + str(FRAMES * LANDMARKS + 2), r.stderr)


if __name__ == "__main__":
    script_test.main(sys.modules[__name__])
