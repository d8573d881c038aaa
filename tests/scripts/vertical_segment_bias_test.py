#!/usr/bin/env python3
"""Tests of scripts/vertical_segment_bias.py on small segment files written here."""
import os
import subprocess
import sys
import tempfile
import unittest

import script_test

SCRIPT = None
HEADER = "set,frame,inlier,true_deg,est_deg,x0,length_px,ua,va,ub,vb\n"


def row(inlier, true_deg, x0, length, va, vb, name="s"):
    return f"{name},0,{inlier},{true_deg},0,{x0},{length},0,{va},0,{vb}\n"


class VerticalSegmentBias(unittest.TestCase):
    def run_script(self, text, *args):
        with tempfile.TemporaryDirectory() as d:
            path = os.path.join(d, "segments.csv")
            with open(path, "w") as f:
                f.write(text)
            return subprocess.run([sys.executable, SCRIPT, path, *args], capture_output=True,
                                  text=True)

    def test_each_segment_lands_in_its_region_and_band(self):
        text = HEADER
        # Above the principal row (100), right of centre, short: -0.2 and -0.1 deg, lengths 30
        # and 10: weighted mean -0.175. Across the row, left: +0.1. An outlier is left out.
        text += row(1, -0.2, 0.3, 30, 20, 50) + row(1, -0.1, 0.3, 10, 60, 70)
        text += row(1, 0.1, -0.5, 100, 50, 150)
        text += row(0, 5.0, 0.3, 30, 20, 50)
        out = self.run_script(text, "--cv", "100")
        self.assertEqual(out.returncode, 0, out.stderr)
        lines = out.stdout.splitlines()
        self.assertIn("3 inlier segments", lines[0])
        above = next(l for l in lines if l.startswith("above "))
        cells = [c.strip() for c in above.split("|")[1:]]
        self.assertEqual(cells[3], "2 -0.175", out.stdout)
        self.assertEqual(cells[0], "0    -", out.stdout)
        across = next(l for l in lines if l.startswith("across"))
        self.assertEqual([c.strip() for c in across.split("|")[1:]][0], "1 +0.100", out.stdout)
        short = next(l for l in lines if l.strip().startswith("0-50 px"))
        self.assertEqual([c.strip() for c in short.split("|")[1:]][3], "2 -0.175", out.stdout)

    def test_one_set_of_several(self):
        text = HEADER + row(1, 0.2, 0.0, 40, 10, 20, "a") + row(1, -0.4, 0.0, 40, 10, 20, "b")
        out = self.run_script(text, "--cv", "100", "--set", "b")
        self.assertEqual(out.returncode, 0, out.stderr)
        self.assertIn("1 inlier segments, length-weighted mean angle from the true up -0.400 deg",
                      out.stdout)

    def test_bad_input_is_named(self):
        out = self.run_script(HEADER + row(1, "x", 0.0, 40, 10, 20), "--cv", "100")
        self.assertNotEqual(out.returncode, 0)
        self.assertIn("segments.csv:2: field 'true_deg': not a number: 'x'", out.stderr)
        out = self.run_script("set,frame,valid\ns,0,1\n", "--cv", "100")
        self.assertNotEqual(out.returncode, 0)
        self.assertIn("no column inlier (not a --segments-csv file)", out.stderr)
        out = self.run_script(HEADER + row(0, 0.1, 0.0, 40, 10, 20), "--cv", "100")
        self.assertNotEqual(out.returncode, 0)
        self.assertIn("no inlier segments", out.stderr)


if __name__ == "__main__":
    script_test.main(sys.modules[__name__])
