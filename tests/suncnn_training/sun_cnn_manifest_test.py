#!/usr/bin/env python3
"""Tests of the Sun-CNN manifest (estimator/suncnn/training/sun_cnn_manifest.py) and of
train_sun_cnn.sh's --real path, on the 11 real KITTI 00 frames. Python only (no PyTorch).

    sun_cnn_manifest_test.py --manifest-script M --train-script T --frames DIR --sun-csv CSV
                             --work DIR [unittest arguments, e.g. a test class name]
"""
import argparse
import csv
import hashlib
import json
import os
import shutil
import subprocess
import sys
import unittest

ARGS = None


def read_sun(path):
    with open(path, newline="") as f:
        return {int(r["frame"]): [float(r["sx"]), float(r["sy"]), float(r["sz"])]
                for r in csv.DictReader(f)}


def read_manifest(path):
    with open(path, newline="") as f:
        return list(csv.DictReader(f))


def frame_images(folder):
    """{(camera, frame)} of the images in a KITTI odometry folder."""
    out = set()
    for cam in ("image_0", "image_1", "image_2", "image_3"):
        d = os.path.join(folder, cam)
        if os.path.isdir(d):
            out |= {(cam, int(os.path.splitext(n)[0])) for n in os.listdir(d) if n.endswith(".png")}
    return out


class Base(unittest.TestCase):
    def setUp(self):
        self.work = os.path.join(ARGS.work, self.id().split(".")[-2] + "_" + self._testMethodName)
        shutil.rmtree(self.work, ignore_errors=True)
        os.makedirs(self.work)

    def manifest(self, *args, expect_ok=True):
        out = os.path.join(self.work, "manifest.csv")
        p = subprocess.run([sys.executable, ARGS.manifest_script, "--out", out, *args],
                           capture_output=True, text=True)
        if expect_ok:
            self.assertEqual(p.returncode, 0, p.stderr)
        return out, p

    def corrupt_csv(self, line_no, text):
        """The first 6 lines of the sun file (frames 0-4) with line line_no replaced."""
        with open(ARGS.sun_csv) as f:
            lines = f.read().splitlines()[:6]
        lines[line_no - 1] = text
        path = os.path.join(self.work, "sun_bad.csv")
        with open(path, "w") as f:
            f.write("\n".join(lines) + "\n")
        return path


class RealFrames(Base):
    def test_every_frame_with_an_image_and_a_sun_row(self):
        out, _ = self.manifest("--real", f"{ARGS.frames}:{ARGS.sun_csv}")
        rows = read_manifest(out)
        sun = read_sun(ARGS.sun_csv)
        images = frame_images(ARGS.frames)
        expected = {(cam, k) for cam, k in images if k in sun}
        self.assertGreater(len(expected), 0)
        self.assertEqual(len(rows), len(expected))
        seen = set()
        for r in rows:
            self.assertEqual(r["split"], "test")  # the default: held out
            self.assertEqual(r["scenario"],
                             "real_" + os.path.basename(os.path.normpath(ARGS.frames)))
            path = r["image"]
            self.assertTrue(os.path.isabs(path), path)  # outside any renders folder
            self.assertTrue(os.path.isfile(path), path)
            cam = os.path.basename(os.path.dirname(path))
            k = int(os.path.splitext(os.path.basename(path))[0])
            seen.add((cam, k))
            for got, want in zip((r["sx"], r["sy"], r["sz"]), sun[k]):
                self.assertAlmostEqual(float(got), want, places=6)
        self.assertEqual(seen, expected)
        # No training rows: the hash is that of no data.
        with open(out + ".sha256") as f:
            self.assertEqual(f.read().strip(), hashlib.sha256().hexdigest())

    def test_only_frames_that_have_a_sun_row(self):
        sun_csv = self.corrupt_csv(1, "frame,sx,sy,sz")  # frames 0-4 only, unchanged
        out, _ = self.manifest("--real", f"{ARGS.frames}:{sun_csv}:val")
        rows = read_manifest(out)
        frames = {int(os.path.splitext(os.path.basename(r["image"]))[0]) for r in rows}
        self.assertEqual(frames, {0, 1, 2, 3, 4})
        self.assertTrue(all(r["split"] == "val" for r in rows))

    def test_training_rows_come_in_stereo_pairs_and_are_hashed(self):
        out, _ = self.manifest("--real", f"{ARGS.frames}:{ARGS.sun_csv}:train")
        rows = read_manifest(out)
        self.assertEqual(len(rows) % 2, 0)
        for left, right in zip(rows[0::2], rows[1::2]):
            self.assertEqual(left["split"], "train")
            self.assertEqual(os.path.basename(left["image"]), os.path.basename(right["image"]))
            self.assertEqual(os.path.basename(os.path.dirname(left["image"])), "image_0")
            self.assertEqual(os.path.basename(os.path.dirname(right["image"])), "image_1")
        # The hash as the manifest's docstring defines it, over the real training rows.
        name = "real_" + os.path.basename(os.path.normpath(ARGS.frames))
        h = hashlib.sha256()
        keyed = sorted((f"{name}/{os.path.basename(os.path.dirname(r['image']))}/"
                        f"{os.path.basename(r['image'])}", r["image"]) for r in rows)
        for key, path in keyed + [(f"{name}/{os.path.basename(ARGS.sun_csv)}", ARGS.sun_csv)]:
            h.update(key.encode() + b"\0")
            with open(path, "rb") as f:
                h.update(f.read())
        with open(out + ".sha256") as f:
            self.assertEqual(f.read().strip(), h.hexdigest())


class WithRenders(Base):
    """A fake renders folder (one train_ and one val_ drive of 2 frames): real held-out rows
    leave the training hash as it was, real training rows change it."""

    def make_renders(self):
        renders = os.path.join(self.work, "renders")
        for scen in ("train_a", "val_b"):
            d = os.path.join(renders, scen, "2026_01_01", "2026_01_01_drive_0001_sync")
            os.makedirs(os.path.join(d, "gt"))
            with open(os.path.join(d, "gt", "sun_cam0.csv"), "w") as f:
                f.write("frame,sx,sy,sz\n0,0.6,-0.8,0\n1,0,-0.6,0.8\n")
            for cam in ("image_02", "image_03"):
                os.makedirs(os.path.join(d, cam, "data"))
                for k in range(2):
                    with open(os.path.join(d, cam, "data", f"{k:010d}.png"), "wb") as f:
                        f.write(f"{scen} {cam} {k}".encode())
            with open(os.path.join(renders, scen, "RENDERED"), "w") as f:
                f.write("x\n")
        return renders

    def test_hash_and_rows(self):
        renders = self.make_renders()

        def run(*extra):
            out, _ = self.manifest("--renders", renders, *extra)
            with open(out + ".sha256") as f:
                return read_manifest(out), f.read().strip()

        rows, alone = run()
        self.assertEqual([r["split"] for r in rows], ["train"] * 4 + ["val"] * 4)
        self.assertTrue(all(not os.path.isabs(r["image"]) for r in rows))
        rows, held_out = run("--real", f"{ARGS.frames}:{ARGS.sun_csv}")
        self.assertEqual(held_out, alone)
        self.assertEqual(sum(r["split"] == "test" for r in rows), len(rows) - 8)
        _, trained = run("--real", f"{ARGS.frames}:{ARGS.sun_csv}:train")
        self.assertNotEqual(trained, alone)


class CorruptCsv(Base):
    def expect_error(self, sun_csv, *needles):
        _, p = self.manifest("--real", f"{ARGS.frames}:{sun_csv}", expect_ok=False)
        self.assertNotEqual(p.returncode, 0)
        for n in (sun_csv,) + needles:
            self.assertIn(n, p.stderr)
        self.assertNotIn("Traceback", p.stderr)

    def test_a_bad_number_names_file_line_and_field(self):
        self.expect_error(self.corrupt_csv(4, "2,0.23384,abc,-0.78511"), "line 4", "field sy")

    def test_a_short_line_names_the_missing_field(self):
        self.expect_error(self.corrupt_csv(3, "1,0.23512,-0.57275"), "line 3", "field sz")

    def test_a_bad_frame_number(self):
        self.expect_error(self.corrupt_csv(5, "x3,0.23257,-0.57428,-0.78493"), "line 5",
                          "field frame")

    def test_not_a_unit_vector(self):
        self.expect_error(self.corrupt_csv(2, "0,0.5,0.5,0.5"), "line 2", "sx,sy,sz")

    def test_a_wrong_header(self):
        self.expect_error(self.corrupt_csv(1, "frame,x,y,z"), "line 1", "header")

    def test_bad_arguments(self):
        for args, needle in ((["--real", f"{ARGS.frames}:{ARGS.sun_csv}:training"], "SPLIT"),
                             (["--real", f"{ARGS.frames}"], "DIR:CSV"),
                             (["--real", f"/nonexistent:{ARGS.sun_csv}"], "/nonexistent"),
                             ([], "--renders")):
            _, p = self.manifest(*args, expect_ok=False)
            self.assertNotEqual(p.returncode, 0, args)
            self.assertIn(needle, p.stderr, args)


class TrainScript(Base):
    def test_real_folders_pass_through_to_the_manifest(self):
        """--no-render --render-only: no rendering, no training, only the manifest."""
        renders = os.path.join(self.work, "renders")
        env = dict(os.environ, SUNVO_RENDERS=renders)
        p = subprocess.run(["bash", ARGS.train_script, "--no-render", "--render-only", "--real",
                            f"{ARGS.frames}:{ARGS.sun_csv}:val"],
                           capture_output=True, text=True, env=env)
        self.assertEqual(p.returncode, 0, p.stderr)
        rows = read_manifest(os.path.join(renders, "sun_cnn_manifest.csv"))
        self.assertEqual(len(rows), len(frame_images(ARGS.frames)))
        self.assertTrue(all(r["split"] == "val" for r in rows))
        p = subprocess.run(["bash", ARGS.train_script, "--no-render", "--real"],
                           capture_output=True, text=True, env=env)
        self.assertEqual(p.returncode, 2)
        self.assertIn("--real needs", p.stderr)


class EndToEnd(Base):
    """The real frames through the manifest (frames 0-5 train, 6-10 val), the trainer (one epoch:
    the path is tested, not the accuracy; 12 images are far too few) and sunvo_sun_eval with the
    model it wrote."""

    def test_real_frames_train_and_appear_in_the_evaluation(self):
        if not ARGS.trainer or not ARGS.sun_eval:
            self.skipTest("needs --trainer and --sun-eval")
        with open(ARGS.sun_csv) as f:
            lines = f.read().splitlines()
        parts = {"train": lines[0:7], "val": [lines[0]] + lines[7:12]}  # header + frames
        args = []
        for split, part in parts.items():
            path = os.path.join(self.work, f"sun_{split}.csv")
            with open(path, "w") as f:
                f.write("\n".join(part) + "\n")
            args += ["--real", f"{ARGS.frames}:{path}:{split}"]
        manifest, _ = self.manifest(*args)
        model_dir = os.path.join(self.work, "model")
        os.makedirs(model_dir)
        p = subprocess.run([sys.executable, ARGS.trainer, "--manifest", manifest, "--out-dir",
                            model_dir, "--reference", os.path.join(model_dir, "reference.txt"),
                            "--epochs", "1", "--threads", "1"],
                           capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        name = "real_" + os.path.basename(os.path.normpath(ARGS.frames))
        self.assertIn(name, p.stderr)  # the held-out report names the real scenario
        model = os.path.join(model_dir, "sun_cnn.onnx")
        self.assertGreater(os.path.getsize(model), 1000)
        with open(os.path.join(model_dir, "sun_cnn.json")) as f:
            meta = json.load(f)
        grey = meta["gray_input"]  # a colour model's calibration for grey cameras
        self.assertGreater(grey["sigma_scale"], 0.0)
        self.assertIn("val", grey["results"])
        # The sun-elevation gain (sun_cnn_model.calibrate_elevation), one of its grid, per input.
        for gain in (meta["elevation_gain"], grey["elevation_gain"]):
            self.assertIn(gain, (0.0, 0.003, 0.01, 0.03, 0.1, 0.3, 1.0))
        # sun_cnn_calibrate.py --grey-only re-chooses the grey numbers and keeps the colour ones.
        with open(os.path.join(model_dir, "sun_cnn.json")) as f:
            before = json.load(f)
        p = subprocess.run([sys.executable, os.path.join(os.path.dirname(ARGS.trainer),
                                                         "sun_cnn_calibrate.py"),
                            "--manifest", manifest, "--model", model, "--grey-only"],
                           capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        self.assertIn("grey input: elevation_gain", p.stderr)
        with open(os.path.join(model_dir, "sun_cnn.json")) as f:
            after = json.load(f)
        for key in ("sigma_scale", "max_valid_sigma_rad", "elevation_gain", "results"):
            self.assertEqual(after[key], before[key], key)
        self.assertGreater(after["gray_input"]["sigma_scale"], 0.0)
        # A full re-calibration on a manifest without the training rows: the training split keeps
        # its old scores, under a name that says so.
        val_only = os.path.join(self.work, "manifest_val.csv")
        with open(manifest) as f, open(val_only, "w") as g:
            g.writelines(line for line in f if not line.startswith("train,"))
        p = subprocess.run([sys.executable, os.path.join(os.path.dirname(ARGS.trainer),
                                                         "sun_cnn_calibrate.py"),
                            "--manifest", val_only, "--model", model],
                           capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(os.path.join(model_dir, "sun_cnn.json")) as f:
            recal = json.load(f)
        self.assertEqual(sorted(recal["results"]), ["val"])
        self.assertEqual(recal["results_previous_calibration"]["train"], before["results"]["train"])
        out = os.path.join(self.work, "eval")
        p = subprocess.run([ARGS.sun_eval, "--images", ARGS.frames, "--estimators", "sun_cnn",
                            "--model", model, "--out", out, "--debug", "0"],
                           capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        set_name = os.path.basename(os.path.normpath(ARGS.frames))
        self.assertIn(f"| sun_cnn | {set_name} | 11 |", p.stdout)

    def study(self, tool, splits):
        """Runs a study tool of the training folder on the shipped colour model, with the real
        frames split by their rows of the sun file (split -> frame indices); returns its tables."""
        with open(ARGS.sun_csv) as f:
            header, *rows = f.read().splitlines()
        args = []
        name = os.path.splitext(tool)[0]
        for split, frames in splits.items():
            path = os.path.join(self.work, f"{name}_{split}.csv")
            with open(path, "w") as f:
                f.write("\n".join([header] + [rows[i] for i in frames]) + "\n")
            args += ["--real", f"{ARGS.frames}:{path}:{split}"]
        manifest, _ = self.manifest(*args)
        tools = os.path.dirname(os.path.abspath(ARGS.trainer))
        model = os.path.join(tools, "..", "..", "..", "config", "sun_cnn.onnx")
        table = os.path.join(self.work, f"{name}.md")
        p = subprocess.run([sys.executable, os.path.join(tools, tool), "--manifest", manifest,
                            "--model", model, "--out", table], capture_output=True, text=True)
        self.assertEqual(p.returncode, 0, p.stderr)
        with open(table) as f:
            return f.read()

    def test_uncertainty_signals_run_on_the_shipped_model(self):
        """sun_cnn_signals.py (the flip/gamma views and the sun's elevation, docs/
        sun_cnn_calibration.md) on the real frames as validation (0-5) and test (6-10) rows: one
        row per view and gain, the ranking table and three calibrations per split."""
        if not ARGS.trainer:
            self.skipTest("needs --trainer")
        text = self.study("sun_cnn_signals.py", {"val": range(0, 6), "test": range(6, 11)})
        self.assertEqual(text.count("\n| flip |"), 5)
        self.assertEqual(text.count("\n| plain | 0 |"), 1)
        self.assertEqual(text.count("\n| val | "), 1 + 3)  # the ranking row, three calibrations
        self.assertEqual(text.count("\n| test | "), 1 + 3)

    def test_feature_distance_study_runs_on_the_shipped_model(self):
        """sun_cnn_ood.py (the trunk features' distance from the training images', docs/
        sun_cnn_calibration.md) on the real frames as training (0-3), validation (4-7) and test
        (8-10) rows: a distance row per split and real folder, the AUC rows, and one calibration
        row per signal, form and gain."""
        if not ARGS.trainer:
            self.skipTest("needs --trainer")
        text = self.study("sun_cnn_ood.py", {"train": range(0, 4), "val": range(4, 8),
                                             "test": range(8, 11)})
        for split in ("train", "val", "test"):
            self.assertIn(f"\n| {split} | ", text)
        self.assertEqual(text.count("\n| real_"), 1)  # the test split's real folder
        self.assertEqual(text.count("\n| val, "), 2)
        self.assertEqual(text.count("\n| trunk | weak |"), 5)  # FEATURE_GAINS
        self.assertEqual(text.count("\n| fc1 | far |"), 5)

    def test_confidence_head_study_runs_on_the_shipped_model(self):
        """sun_cnn_head.py (a learned confidence head, docs/sun_cnn_calibration.md) on the real
        frames as validation (0-6; one drive, so its folds are frames) and test (7-10) rows: the
        shipped sigma's row and one row per form, signal set and lambda, and the weights."""
        if not ARGS.trainer:
            self.skipTest("needs --trainer")
        text = self.study("sun_cnn_head.py", {"val": range(0, 7), "test": range(7, 11)})
        self.assertEqual(text.count("\n| shipped sigma |"), 1)
        self.assertEqual(text.count("\n| log-error, scalars |"), 4)  # LAMBDAS
        self.assertEqual(text.count("\n| gross, scalars + z |"), 4)
        self.assertIn("\n| ln tan2 | ", text)

    def test_model_pair_study_runs_on_the_shipped_models(self):
        """sun_cnn_pair.py (the colour and the grey model as one ensemble, docs/
        sun_cnn_calibration.md) on the real frames as validation (0-6) and test (7-10) rows: the
        shipped row, one row per model and the pair, and the pair with the feature term."""
        if not ARGS.trainer:
            self.skipTest("needs --trainer")
        text = self.study("sun_cnn_pair.py", {"val": range(0, 7), "test": range(7, 11)})
        self.assertEqual(text.count("\n| shipped (colour model, its JSON) |"), 1)
        for run in ("colour", "grey", "both"):
            self.assertEqual(text.count(f"\n| {run}, rule on val |"), 1)
        self.assertEqual(text.count("\n| both + colour's feature term"), 1)

    def test_members_trained_apart_join_into_the_same_ensemble(self):
        """Two members trained in two processes (--first-member, --save-members) and joined with
        --load-members export the same model, byte for byte, as one process training both."""
        if not ARGS.trainer:
            self.skipTest("needs --trainer")
        manifest, _ = self.manifest("--real", f"{ARGS.frames}:{ARGS.sun_csv}:train")

        def train(tag, *extra):
            out = os.path.join(self.work, tag)
            os.makedirs(out)
            p = subprocess.run([sys.executable, ARGS.trainer, "--manifest", manifest,
                                "--out-dir", out, "--reference", os.path.join(out, "ref.txt"),
                                "--epochs", "1", "--threads", "1", *extra],
                               capture_output=True, text=True)
            self.assertEqual(p.returncode, 0, p.stderr)
            with open(os.path.join(out, "sun_cnn.onnx"), "rb") as f:
                return f.read(), out

        together, _ = train("together", "--members", "2")
        pt = [os.path.join(self.work, f"m{k}.pt") for k in (0, 1)]
        for k in (0, 1):
            train(f"apart{k}", "--members", "1", "--first-member", str(k), "--save-members", pt[k])
        joined, out = train("joined", "--load-members", *pt)
        self.assertEqual(together, joined)
        with open(os.path.join(out, "sun_cnn.json")) as f:
            self.assertEqual(json.load(f)["mc"]["members"], 2)
        p = subprocess.run([sys.executable, ARGS.trainer, "--manifest", manifest, "--out-dir",
                            out, "--reference", os.path.join(out, "ref.txt"), "--epochs", "2",
                            "--load-members", *pt], capture_output=True, text=True)
        self.assertNotEqual(p.returncode, 0)
        self.assertIn("--load-members", p.stderr)


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    for name in ("--manifest-script", "--train-script", "--frames", "--sun-csv", "--work"):
        ap.add_argument(name, required=True)
    ap.add_argument("--trainer", default="")  # sun_cnn_train.py (EndToEnd only)
    ap.add_argument("--sun-eval", default="")  # the sunvo_sun_eval program (EndToEnd only)
    ARGS, rest = ap.parse_known_args()
    unittest.main(argv=[sys.argv[0]] + rest, verbosity=2)
