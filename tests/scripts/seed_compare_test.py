#!/usr/bin/env python3
"""Tests of scripts/seed_compare.py: the paired statistics against hand-computed values, a study
run end to end through a stand-in experiment program (options reach it, finished runs are not run
again), and bad input (seeds, a missing or malformed metrics file, a failing run) named."""
import json
import os
import stat
import subprocess
import sys
import tempfile
import textwrap
import unittest

import script_test

SCRIPT = None

# A stand-in for sunvo_experiment: pure VO's final drift is 10 + seed, times 1.2 with --worse;
# each call is appended to calls.txt next to the script.
FAKE = textwrap.dedent("""\
    #!{python}
    import json, os, sys
    a = sys.argv[1:]
    seed = int(a[a.index("--seed") + 1]); out = a[a.index("--out") + 1]
    with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "calls.txt"), "a") as f:
        f.write(" ".join(a) + "\\n")
    if "--fail" in a:
        sys.exit(3)
    k = 1.2 if "--worse" in a else 1.0
    for r in a[a.index("--routes") + 1].split(","):
        e = {{"table1": {{"final_drift_m": k * (10 + seed), "rot_armse_rad": 0.02}},
             "kitti_segments": {{"t_err_pct": 0.5}}}}
        json.dump({{"estimates": [e, {{}}]}}, open(os.path.join(out, f"route_{{r}}_metrics.json"), "w"))
    """)


def estimate(name, final, rot=0.02, terr=0.5):
    return {"name": name, "table1": {"final_drift_m": final, "rot_armse_rad": rot},
            "kitti_segments": {"t_err_pct": terr}}


def write_metrics(d, tag, seed, route, final, rot=0.02, terr=0.5, more=()):
    """A metrics file whose first estimate is pure VO; more: further estimates."""
    run = os.path.join(d, f"{tag}_s{seed}")
    os.makedirs(run, exist_ok=True)
    with open(os.path.join(run, f"route_{route}_metrics.json"), "w") as f:
        json.dump({"estimates": [estimate("Pure VO", final, rot, terr), *more]}, f)


class SeedCompare(unittest.TestCase):
    def run_script(self, *args):
        return subprocess.run([sys.executable, SCRIPT, *args], capture_output=True, text=True)

    def test_paired_statistics(self):
        with tempfile.TemporaryDirectory() as d:
            # Changes +10 %, -20 %, +30 %: mean +6.667 %, sample std 25.166 %, se 14.530 %.
            for s, (a, b) in zip((1, 2, 3), ((10.0, 11.0), (5.0, 4.0), (2.0, 2.6))):
                write_metrics(d, "a", s, "00", a)
                write_metrics(d, "b", s, "00", b, rot=0.01, terr=0.5)
            out = os.path.join(d, "stats.json")
            r = self.run_script("--compare-only", "--out", d, "--routes", "00", "--seeds", "1-3",
                                "--json", out)
            self.assertEqual(r.returncode, 0, r.stderr)
            st = json.load(open(out))["00"]
            final = st["final drift [m]"]
            self.assertAlmostEqual(final["mean_a"], 17.0 / 3.0)
            self.assertAlmostEqual(final["mean_b"], 17.6 / 3.0)
            self.assertAlmostEqual(final["mean_change_pct"], 20.0 / 3.0)
            self.assertAlmostEqual(final["se_pct"], 14.529663, places=5)
            self.assertEqual(final["worse"], 2)
            self.assertAlmostEqual(final["ratio_of_means"], 17.6 / 17.0)
            self.assertAlmostEqual(st["rot. ARMSE [1e-3]"]["mean_change_pct"], -50.0)
            self.assertEqual(st["rot. ARMSE [1e-3]"]["worse"], 0)
            self.assertAlmostEqual(st["t_err [%]"]["mean_change_pct"], 0.0)
            self.assertIn("worse by >5 % on 2/3", r.stdout)

    def test_a_named_estimate_against_the_other_set_and_its_own_pure_vo(self):
        with tempfile.TemporaryDirectory() as d:
            # Pure VO 10 under both sets; the fused row 8 / 11 (A) and 6 / 12 (B) on seeds 1 / 2.
            for s, (fa, fb) in zip((1, 2), ((8.0, 6.0), (11.0, 12.0))):
                write_metrics(d, "a", s, "00", 10.0, more=[estimate("VO+Sun", fa)])
                write_metrics(d, "b", s, "00", 10.0, more=[estimate("VO+Sun", fb)])
            out = os.path.join(d, "stats.json")
            r = self.run_script("--compare-only", "--out", d, "--routes", "00", "--seeds", "1,2",
                                "--estimate", "VO+Sun", "--json", out)
            self.assertEqual(r.returncode, 0, r.stderr)
            st = json.load(open(out))["00"]
            # B against A: -25 % and +9.09 %.
            self.assertAlmostEqual(st["final drift [m]"]["mean_change_pct"],
                                   50.0 * (-0.25 + 1.0 / 11.0))
            self.assertAlmostEqual(st["final drift [m]"]["mean_b"], 9.0)
            # Each set against its own pure VO: A -20 % / +10 %, B -40 % / +20 %.
            self.assertAlmostEqual(st["A against pure VO: final drift [m]"]["mean_change_pct"], -5.0)
            self.assertEqual(st["A against pure VO: final drift [m]"]["worse"], 1)
            self.assertAlmostEqual(st["B against pure VO: final drift [m]"]["mean_change_pct"], -10.0)
            self.assertEqual(st["B against pure VO: final drift [m]"]["worse"], 1)
            self.assertIn("route 00, VO+Sun:", r.stdout)
            # A name that is not in the table is named with the file and the names it has.
            r = self.run_script("--compare-only", "--out", d, "--routes", "00", "--seeds", "1",
                                "--estimate", "VO+Moon")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("no estimate 'VO+Moon'", r.stderr)
            self.assertIn("'Pure VO', 'VO+Sun'", r.stderr)

    def test_runs_a_study_and_resumes(self):
        with tempfile.TemporaryDirectory() as d:
            fake = os.path.join(d, "fake_experiment")
            with open(fake, "w") as f:
                f.write(FAKE.format(python=sys.executable))
            os.chmod(fake, os.stat(fake).st_mode | stat.S_IXUSR)
            out = os.path.join(d, "study")
            js = os.path.join(d, "s.json")
            args = ["--experiment", fake, "--data", "/some/data", "--routes", "00,06",
                    "--seeds", "1,2", "--out", out, "--b", "--worse --x 1", "--jobs", "2",
                    "--json", js]
            r = self.run_script(*args)
            self.assertEqual(r.returncode, 0, r.stderr)
            for route in ("00", "06"):
                final = json.load(open(js))[route]["final drift [m]"]
                self.assertAlmostEqual(final["mean_a"], 11.5)
                self.assertAlmostEqual(final["mean_change_pct"], 20.0)
                self.assertEqual(final["worse"], 2)
            calls = open(os.path.join(d, "calls.txt")).read().splitlines()
            self.assertEqual(len(calls), 4)
            self.assertEqual(sum("--worse --x 1" in c for c in calls), 2)
            self.assertTrue(all("--data /some/data" in c for c in calls))
            # Finished runs are read, not run again.
            r = self.run_script(*args)
            self.assertEqual(r.returncode, 0, r.stderr)
            self.assertEqual(len(open(os.path.join(d, "calls.txt")).read().splitlines()), 4)
            # A failing run is named with its log.
            r = self.run_script("--experiment", fake, "--seeds", "7", "--out", out,
                                "--b=--fail")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("exited with 3", r.stderr)
            self.assertIn("b_s7", r.stderr)

    def test_bad_input_is_named(self):
        with tempfile.TemporaryDirectory() as d:
            r = self.run_script("--compare-only", "--out", d, "--seeds", "3-1")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("--seeds: '3-1'", r.stderr)
            r = self.run_script("--compare-only", "--out", d, "--seeds", "x")
            self.assertIn("--seeds: 'x'", r.stderr)
            write_metrics(d, "a", 1, "00", 10.0)
            r = self.run_script("--compare-only", "--out", d, "--routes", "00", "--seeds", "1")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn(os.path.join(d, "b_s1", "route_00_metrics.json") + ": missing",
                          r.stderr)
            os.makedirs(os.path.join(d, "b_s1"))
            with open(os.path.join(d, "b_s1", "route_00_metrics.json"), "w") as f:
                f.write('{"estimates": []}')
            r = self.run_script("--compare-only", "--out", d, "--routes", "00", "--seeds", "1")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("not a metrics file", r.stderr)
            r = self.run_script("--experiment", os.path.join(d, "nope"), "--out", d,
                                "--seeds", "1")
            self.assertNotEqual(r.returncode, 0)
            self.assertIn("is not executable", r.stderr)


if __name__ == "__main__":
    script_test.main(sys.modules[__name__])
