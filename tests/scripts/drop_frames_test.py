#!/usr/bin/env python3
"""Tests of scripts/drop_frames.py: the kept frames are numbered on without a gap in every file,
their times, poses and sun rows are the originals', the draw repeats for a seed, a stretch
(--range) starts its ground truth at the identity, and bad input names the file and line."""
import os
import subprocess
import sys
import tempfile
import unittest

import script_test

SCRIPT = None
FRAMES, LANDMARKS = 40, 6


class DropFrames(unittest.TestCase):
    def run_script(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)

    def write_folder(self, d):
        os.makedirs(d)
        files = {
            "calib.txt": "700 700 600 180 0.5\n",
            "times.txt": "".join(f"{0.1 * k:.1f}\n" for k in range(FRAMES)),
            # The pose's x translation and the sun's sx carry the original frame number.
            "gt_poses.txt": "".join(f"1 0 0 {k} 0 1 0 0 0 0 1 0\n" for k in range(FRAMES)),
            "sun_cam.csv": "frame,sx,sy,sz\n" + "".join(f"{k},{k},0,1\n" for k in range(FRAMES)),
            "tracks.csv": "frame,landmark,uL,vL,uR,vR\n" + "".join(
                f"{k},{i},{100 + k},{50 + i},{90 + k},{50 + i}\n"
                for k in range(FRAMES) for i in range(LANDMARKS)),
        }
        for name, text in files.items():
            with open(os.path.join(d, name), "w") as f:
                f.write(text)

    def read(self, folder, name):
        with open(os.path.join(folder, name)) as f:
            return f.read().splitlines()

    def original_frames(self, out):
        """The original frame number of each output frame, from times.txt, checked in every file."""
        times = [round(float(t) * 10) for t in self.read(out, "times.txt")]
        poses = [int(float(p.split()[3])) for p in self.read(out, "gt_poses.txt")]
        sun = self.read(out, "sun_cam.csv")
        self.assertEqual(sun[0], "frame,sx,sy,sz")
        self.assertEqual([int(r.split(",")[0]) for r in sun[1:]], list(range(len(times))))
        self.assertEqual([int(r.split(",")[1]) for r in sun[1:]], times)
        self.assertEqual(poses, times)
        tracks = [r.split(",") for r in self.read(out, "tracks.csv")[1:]]
        for row in tracks:  # uL = 100 + the original frame
            self.assertEqual(times[int(row[0])], int(row[2]) - 100)
        self.assertEqual(len(tracks), LANDMARKS * len(times))
        return times

    def test_every_nth_frame(self):
        with tempfile.TemporaryDirectory() as d:
            src, out = os.path.join(d, "src"), os.path.join(d, "out")
            self.write_folder(src)
            r = self.run_script(src, out, "--every", "4")
            self.assertEqual(r.returncode, 0, r.stderr)
            kept = self.original_frames(out)
            self.assertEqual(kept, [k for k in range(FRAMES) if (k + 1) % 4 != 0])
            self.assertTrue(os.path.isfile(os.path.join(out, "calib.txt")))

    def test_random_drop_repeats_for_a_seed(self):
        with tempfile.TemporaryDirectory() as d:
            src = os.path.join(d, "src")
            self.write_folder(src)
            runs = {}
            for name, seed in (("a", "3"), ("b", "3"), ("c", "4")):
                r = self.run_script(src, os.path.join(d, name), "--drop", "0.3", "--seed", seed)
                self.assertEqual(r.returncode, 0, r.stderr)
                runs[name] = self.original_frames(os.path.join(d, name))
            self.assertEqual(runs["a"][0], 0)  # the first frame is always kept
            self.assertLess(len(runs["a"]), FRAMES)
            self.assertEqual(runs["a"], runs["b"])
            self.assertNotEqual(runs["a"], runs["c"])

    def test_a_stretch_starts_at_the_identity(self):
        with tempfile.TemporaryDirectory() as d:
            src, out = os.path.join(d, "src"), os.path.join(d, "out")
            self.write_folder(src)
            # The poses turn 90 deg about y per frame pair from frame 10 on: R(k) = Ry(90 (k >= 10)),
            # t = (k, 0, 0); frames 12..17 kept.
            rot = "0 0 1 {k} 0 1 0 0 -1 0 0 0\n"
            with open(os.path.join(src, "gt_poses.txt"), "w") as f:
                f.write("".join(rot.format(k=k) if k >= 10 else f"1 0 0 {k} 0 1 0 0 0 0 1 0\n"
                                for k in range(FRAMES)))
            r = self.run_script(src, out, "--range", "12", "6")
            self.assertEqual(r.returncode, 0, r.stderr)
            times = [round(float(t) * 10) for t in self.read(out, "times.txt")]
            self.assertEqual(times, list(range(12, 18)))
            poses = [[float(x) for x in p.split()] for p in self.read(out, "gt_poses.txt")]
            self.assertEqual(len(poses), 6)
            for i, p in enumerate(poses):
                # R_first^T R = I; R_first^T (t - t_first) = Ry(90)^T (i, 0, 0) = (0, 0, i).
                expected = [1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, i]
                for got, want in zip(p, expected):
                    self.assertAlmostEqual(got, want, places=9)
            tracks = [r.split(",") for r in self.read(out, "tracks.csv")[1:]]
            self.assertEqual(sorted({int(t[0]) for t in tracks}), list(range(6)))
            self.assertEqual({int(t[2]) - 100 - int(t[0]) for t in tracks}, {12})
            sun = self.read(out, "sun_cam.csv")
            self.assertEqual([int(r.split(",")[1]) for r in sun[1:]], list(range(12, 18)))
            r = self.run_script(src, os.path.join(d, "out2"), "--range", "38", "3")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("--range 38 3", r.stderr)

    def test_bad_input_names_the_file(self):
        with tempfile.TemporaryDirectory() as d:
            r = self.run_script(os.path.join(d, "none"), os.path.join(d, "out"), "--every", "2")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("tracks.csv", r.stderr)
            src = os.path.join(d, "src")
            self.write_folder(src)
            r = self.run_script(src, os.path.join(d, "out"), "--drop", "1")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("--drop", r.stderr)
            with open(os.path.join(src, "tracks.csv"), "a") as f:
                f.write(f"{FRAMES},0,1,2,3,4\n")
            r = self.run_script(src, os.path.join(d, "out2"), "--every", "2")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn(f"tracks.csv:{FRAMES * LANDMARKS + 2}: field 'frame'", r.stderr)


if __name__ == "__main__":
    script_test.main(sys.modules[__name__])
