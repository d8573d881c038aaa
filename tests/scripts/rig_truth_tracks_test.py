#!/usr/bin/env python3
"""Tests of scripts/rig_truth_tracks.py: right observations seen by a turned camera come back to
where the nominal camera sees them."""
import csv
import math
import os
import subprocess
import sys
import tempfile
import unittest

import script_test

SCRIPT = None
FU, FV, CU, CV = 700.0, 700.0, 600.0, 180.0


def turned(p, roll, pitch, yaw):
    """p in the nominal right camera -> p in the camera turned by Rz(roll) Rx(pitch) Ry(yaw)."""
    def rot_t(axis, a, v):  # R(axis, a)^T v
        c, s = math.cos(a), math.sin(-a)
        x, y, z = v
        if axis == "z":
            return (c * x - s * y, s * x + c * y, z)
        if axis == "x":
            return (x, c * y - s * z, s * y + c * z)
        return (c * x + s * z, y, -s * x + c * z)
    # (Rz Rx Ry)^T = Ry^T Rx^T Rz^T
    return rot_t("y", yaw, rot_t("x", pitch, rot_t("z", roll, p)))


def project(p):
    return FU * p[0] / p[2] + CU, FV * p[1] / p[2] + CV


class RigTruthTracks(unittest.TestCase):
    def run_script(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)

    def write_folder(self, d, angles_deg, points):
        tracks = os.path.join(d, "tracks")
        os.makedirs(tracks)
        with open(os.path.join(tracks, "calib.txt"), "w") as f:
            f.write(f"{FU} {FV} {CU} {CV} 0.5 1200 370\n")
        with open(os.path.join(tracks, "times.txt"), "w") as f:
            f.write("0\n")
        with open(os.path.join(d, "rig_error.csv"), "w") as f:
            f.write("frame,right_roll_deg,right_pitch_deg,right_yaw_deg\n")
            f.write("0," + ",".join(str(a) for a in angles_deg) + "\n")
        rad = [math.radians(a) for a in angles_deg]
        with open(os.path.join(tracks, "tracks.csv"), "w") as f:
            f.write("frame,landmark,uL,vL,uR,vR,vR_measured\n")
            for i, p in enumerate(points):
                uR, vR = project(turned(p, *rad))
                f.write(f"0,{i},0,0,{uR:.4f},{vR:.4f},1\n")

    def read_right(self, folder):
        with open(os.path.join(folder, "tracks.csv"), newline="") as f:
            return [(float(r["uR"]), float(r["vR"])) for r in csv.DictReader(f)]

    def test_the_turn_is_taken_out_and_only_the_named_axes(self):
        points = [(x, y, z) for x in (-8.0, 0.0, 9.0) for y in (-2.0, 1.5) for z in (6.0, 40.0)]
        with tempfile.TemporaryDirectory() as d:
            self.write_folder(d, (0.15, 0.03, 0.01), points)
            out = self.run_script(os.path.join(d, "tracks"), os.path.join(d, "rig_error.csv"),
                                  os.path.join(d, "all"))
            self.assertEqual(out.returncode, 0, out.stderr)
            for (uR, vR), p in zip(self.read_right(os.path.join(d, "all")), points):
                u, v = project(p)
                self.assertAlmostEqual(uR, u, delta=2e-4)
                self.assertAlmostEqual(vR, v, delta=2e-4)
            # Yaw alone taken out: what is left is the roll and pitch turn.
            out = self.run_script(os.path.join(d, "tracks"), os.path.join(d, "rig_error.csv"),
                                  os.path.join(d, "yaw"), "--axes", "yaw")
            self.assertEqual(out.returncode, 0, out.stderr)
            rad = (math.radians(0.15), math.radians(0.03), 0.0)
            for (uR, vR), p in zip(self.read_right(os.path.join(d, "yaw")), points):
                u, v = project(turned(p, *rad))
                self.assertAlmostEqual(uR, u, delta=2e-4)
                self.assertAlmostEqual(vR, v, delta=2e-4)

    def test_a_frame_without_a_rig_row_names_the_line(self):
        with tempfile.TemporaryDirectory() as d:
            self.write_folder(d, (0.1, 0.0, 0.0), [(0.0, 0.0, 10.0)])
            with open(os.path.join(d, "tracks", "tracks.csv"), "a") as f:
                f.write("3,9,0,0,500.0,180.0,1\n")
            out = self.run_script(os.path.join(d, "tracks"), os.path.join(d, "rig_error.csv"),
                                  os.path.join(d, "out"))
            self.assertNotEqual(out.returncode, 0)
            self.assertIn("tracks.csv:3: frame 3 has no row in", out.stderr)


if __name__ == "__main__":
    script_test.main(sys.modules[__name__])
