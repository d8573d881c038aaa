#!/usr/bin/env python3
"""Tests of scripts/turn_rig_tracks.py: a turn by 0 keeps the folder, a turn and its inverse give
the observations back, the poses and the sun turn as R T R^T and R s, observations without depth
are left out and counted, and bad input names the file, line and field."""
import math
import os
import subprocess
import sys
import tempfile
import unittest

import script_test

SCRIPT = None
FU, CU, CV, B = 700.0, 600.0, 180.0, 0.5
# Points in the first camera (x right, y down, z ahead), seen in frames 0 and 1 (1 m ahead).
POINTS = [(-4.0, -1.0, 12.0), (3.0, 1.2, 8.0), (0.5, -2.0, 25.0), (-1.5, 1.5, 6.0)]


def project(p):
    x, y, z = p
    return (FU * x / z + CU, FU * y / z + CV, FU * (x - B) / z + CU)


class TurnRigTracks(unittest.TestCase):
    def run_script(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)

    def write_folder(self, d, extra_rows=""):
        os.makedirs(d)
        rows = []
        for k in range(2):
            for i, (x, y, z) in enumerate(POINTS):
                uL, vL, uR = project((x, y, z - k))
                rows.append(f"{k},{i},{uL:.4f},{vL:.4f},{uR:.4f},{vL + 0.1:.4f}\n")
        files = {
            "calib.txt": f"{FU} {FU} {CU} {CV} {B}\n",
            "times.txt": "0.0\n0.1\n",
            "gt_poses.txt": "1 0 0 0 0 1 0 0 0 0 1 0\n1 0 0 0 0 1 0 0 0 0 1 1\n",
            "sun_cam.csv": "frame,sx,sy,sz\n0,0,-1,0\n1,0,-1,0\n",
            "tracks.csv": "frame,landmark,uL,vL,uR,vR\n" + "".join(rows) + extra_rows,
        }
        for name, text in files.items():
            with open(os.path.join(d, name), "w") as f:
                f.write(text)

    def read_tracks(self, d):
        with open(os.path.join(d, "calib.txt")) as f:
            fu, fv, cu, cv = [float(v) for v in f.read().split()[:4]]
        with open(os.path.join(d, "tracks.csv")) as f:
            lines = f.read().splitlines()[1:]
        # Offsets from the principal point, which the script may move.
        return [(int(r[0]), int(r[1]), float(r[2]) - cu, float(r[3]) - cv, float(r[4]) - cu,
                 float(r[5]) - float(r[3])) for r in (l.split(",") for l in lines)]

    def test_a_turn_by_zero_keeps_the_folder(self):
        with tempfile.TemporaryDirectory() as d:
            src, out = os.path.join(d, "src"), os.path.join(d, "out")
            self.write_folder(src)
            r = self.run_script(src, out, "0")
            self.assertEqual(r.returncode, 0, r.stderr)
            for a, b in zip(self.read_tracks(src), self.read_tracks(out)):
                self.assertEqual(a[:2], b[:2])
                for u, v in zip(a[2:], b[2:]):
                    self.assertAlmostEqual(u, v, places=2)
            with open(os.path.join(out, "calib.txt")) as f:
                self.assertEqual(len(f.read().split()), 7)

    def test_a_turn_and_its_inverse_give_the_observations_back(self):
        with tempfile.TemporaryDirectory() as d:
            src = os.path.join(d, "src")
            self.write_folder(src)
            for axis in ("x", "y"):
                there, back = os.path.join(d, "there" + axis), os.path.join(d, "back" + axis)
                self.assertEqual(self.run_script(src, there, "12", "--axis", axis).returncode, 0)
                self.assertEqual(self.run_script(there, back, "-12", "--axis", axis).returncode, 0)
                moved = self.read_tracks(there)
                self.assertGreater(max(abs(a[3] - b[3]) + abs(a[2] - b[2])
                                       for a, b in zip(self.read_tracks(src), moved)), 5.0)
                for a, b in zip(self.read_tracks(src), self.read_tracks(back)):
                    for u, v in zip(a[2:], b[2:]):
                        self.assertAlmostEqual(u, v, delta=2e-3)

    def test_poses_and_sun_turn_with_the_rig(self):
        with tempfile.TemporaryDirectory() as d:
            src, out = os.path.join(d, "src"), os.path.join(d, "out")
            self.write_folder(src)
            self.assertEqual(self.run_script(src, out, "5").returncode, 0)
            a = math.radians(5.0)
            with open(os.path.join(out, "gt_poses.txt")) as f:
                second = [float(v) for v in f.read().splitlines()[1].split()]
            # t' = R (0, 0, 1) for a turn about x; the rotation stays the identity.
            self.assertAlmostEqual(second[3], 0.0, places=9)
            self.assertAlmostEqual(second[7], -math.sin(a), places=9)
            self.assertAlmostEqual(second[11], math.cos(a), places=9)
            self.assertAlmostEqual(second[0] + second[5] + second[10], 3.0, places=9)
            with open(os.path.join(out, "sun_cam.csv")) as f:
                sun = [float(v) for v in f.read().splitlines()[1].split(",")[1:]]
            self.assertAlmostEqual(sun[1], -math.cos(a), places=9)
            self.assertAlmostEqual(sun[2], -math.sin(a), places=9)

    def test_observations_without_depth_are_counted(self):
        with tempfile.TemporaryDirectory() as d:
            src, out = os.path.join(d, "src"), os.path.join(d, "out")
            self.write_folder(src, extra_rows="1,9,100,100,100.5,100\n")
            r = self.run_script(src, out, "3")
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertIn("1 without a positive disparity", r.stdout)
            self.assertEqual(len(self.read_tracks(out)), 2 * len(POINTS))

    def test_bad_input_names_the_file_line_and_field(self):
        with tempfile.TemporaryDirectory() as d:
            r = self.run_script(os.path.join(d, "none"), os.path.join(d, "out"), "5")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("calib.txt", r.stderr)
            src = os.path.join(d, "src")
            self.write_folder(src, extra_rows="1,9,100,abc,90,100\n")
            r = self.run_script(src, os.path.join(d, "out"), "5")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn(f"tracks.csv:{2 * len(POINTS) + 2}: field 'vL'", r.stderr)
            r = self.run_script(src, os.path.join(d, "out"), "50")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("DEG", r.stderr)


if __name__ == "__main__":
    script_test.main(sys.modules[__name__])
