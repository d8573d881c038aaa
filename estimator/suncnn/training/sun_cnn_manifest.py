#!/usr/bin/env python3
"""Lists the labelled Sun-CNN images (rendered and real) and hashes the training data.

Rendered (--renders DIR): for every completely rendered folder DIR/{train,val,test}_*/ (one
sunvo_render drive each, marked by the file RENDERED) it reads gt/sun_cam0.csv and lists the
colour images of both cameras (image_02, image_03: same orientation, so the same sun vector in
the camera frame); train_* rows are split "train", val_* rows "val" (validation: the choices
are made on it) and test_* rows "test" (reported only).

Real (--real DIR:CSV[:SPLIT], repeatable): a KITTI odometry sequence folder (image_0/ image_1/
gray, image_2/ image_3/ colour, NNNNNN.png) or a KITTI raw drive folder (image_00/data/ ...
image_03/data/, NNNNNNNNNN.png) with a per-frame sun file CSV (header frame,sx,sy,sz: the unit
sun vector in camera 0; the rectified cameras share its orientation). SPLIT is train, val or
test (default test: held out, only reported). Rows are written for every frame that has both a
CSV row and an image, per camera, scenario real_<folder name>; a training split keeps only
complete stereo pairs (the trainer visits a frame through one camera of its pair).

Writes the CSV manifest
    split,scenario,image,sx,sy,sz
(a rendered image relative to the --renders folder; a real image as an absolute path) and
<out>.sha256: the SHA-256 over the training split, i.e. over the sorted (relative path, file
bytes) of every rendered train_* image followed by every rendered train_* label file
(gt/sun_cam0.csv) in sorted order, then (only when there are real training rows) over the sorted
(real_<folder>/<camera>/<file>, bytes) of every real training image followed by each real
training sun file's (real_<folder>/<file name>, bytes). Without real training rows the hash is the
renders-only hash of before.
"""
import argparse
import csv
import glob
import hashlib
import math
import os
import sys

SPLITS = ("train", "val", "test")
# (camera directory, file name pattern) of the two layouts; pairs are (left, right).
ODOMETRY_PAIRS = ((("image_0", "{:06d}.png"), ("image_1", "{:06d}.png")),
                  (("image_2", "{:06d}.png"), ("image_3", "{:06d}.png")))
RAW_PAIRS = ((("image_00/data", "{:010d}.png"), ("image_01/data", "{:010d}.png")),
             (("image_02/data", "{:010d}.png"), ("image_03/data", "{:010d}.png")))


def fail(msg):
    raise SystemExit(f"sun_cnn_manifest: {msg}")


def drive_dir(render_dir):
    found = sorted(glob.glob(os.path.join(render_dir, "*", "*_sync")))
    if len(found) != 1:
        fail(f"{render_dir}: expected one *_sync drive, found {len(found)}")
    return found[0]


def parse_real(text):
    """DIR:CSV[:SPLIT] -> (dir, csv, split)."""
    parts = text.split(":")  # folder and file names with a ':' are not supported
    split = "test"
    if len(parts) == 3:
        if parts[2] not in SPLITS:
            fail(f"--real {text}: SPLIT {parts[2]!r} is not one of {', '.join(SPLITS)}")
        split = parts.pop()
    if len(parts) != 2 or not parts[0] or not parts[1]:
        fail(f"--real {text}: expected DIR:CSV[:SPLIT] with SPLIT one of {', '.join(SPLITS)}")
    folder, sun_csv = parts
    if not os.path.isdir(folder):
        fail(f"--real {text}: no folder {folder}")
    if not os.path.isfile(sun_csv):
        fail(f"--real {text}: no sun file {sun_csv}")
    return folder, sun_csv, split


def read_sun_csv(path):
    """{frame: (sx, sy, sz)}; an error names the file, the line and the field."""
    fields = ["frame", "sx", "sy", "sz"]
    out = {}
    with open(path, newline="") as f:
        rows = csv.reader(f)
        header = next(rows, None)
        if header is None or [h.strip() for h in header] != fields:
            fail(f"{path} line 1: header must be {','.join(fields)}, got {header}")
        for row in rows:
            line = rows.line_num
            if not row or all(not c.strip() for c in row):
                continue  # a blank line
            if len(row) != len(fields):
                field = fields[len(row)] if len(row) < len(fields) else "(extra field)"
                fail(f"{path} line {line}: field {field}: expected {len(fields)} fields, "
                     f"got {len(row)}")
            try:
                k = int(row[0])
            except ValueError:
                fail(f"{path} line {line}: field frame: not an integer: {row[0]!r}")
            if k < 0:
                fail(f"{path} line {line}: field frame: negative: {k}")
            if k in out:
                fail(f"{path} line {line}: field frame: frame {k} repeated")
            s = []
            for name, text in zip(fields[1:], row[1:]):
                try:
                    v = float(text)
                except ValueError:
                    fail(f"{path} line {line}: field {name}: not a number: {text!r}")
                if not math.isfinite(v):
                    fail(f"{path} line {line}: field {name}: not finite: {text!r}")
                s.append(v)
            n = math.sqrt(sum(v * v for v in s))
            if abs(n - 1.0) > 0.01:
                fail(f"{path} line {line}: fields sx,sy,sz: not a unit vector (norm {n:.4f})")
            out[k] = s
    return out


def real_rows(folder, sun_csv, split):
    """Manifest rows of one real folder, and (hash key, path) of its training images."""
    folder = os.path.abspath(folder)
    name = os.path.basename(os.path.normpath(folder))
    scenario = f"real_{name}"
    suns = read_sun_csv(sun_csv)
    layouts = [p for p in ODOMETRY_PAIRS + RAW_PAIRS
               if any(os.path.isdir(os.path.join(folder, cam)) for cam, _ in p)]
    if not layouts:
        fail(f"{folder}: no image_0..image_3 (KITTI odometry) or image_00..image_03/data "
             "(KITTI raw) folder")
    rows, hashed, lone = [], [], 0
    for k in sorted(suns):
        for pair in layouts:
            images = [(cam, os.path.join(folder, cam, pattern.format(k))) for cam, pattern in pair]
            present = [(cam, p) for cam, p in images if os.path.isfile(p)]
            if split == "train" and len(present) == 1:
                lone += 1  # the trainer needs both cameras of a training frame
                continue
            for cam, path in present:
                rows.append([split, scenario, path] + [f"{v:.6f}" for v in suns[k]])
                if split == "train":
                    hashed.append((f"{scenario}/{cam}/{os.path.basename(path)}", path))
    if not rows:
        fail(f"{folder}: no frame has both an image and a row in {sun_csv}")
    if lone:
        print(f"sun_cnn_manifest: {folder}: {lone} training frame(s) without both cameras "
              "left out", file=sys.stderr)
    return rows, hashed


def render_rows(renders):
    rows, train_images, train_labels = [], [], []
    for render_dir in sorted(glob.glob(os.path.join(renders, "train_*")) +
                             glob.glob(os.path.join(renders, "val_*")) +
                             glob.glob(os.path.join(renders, "test_*"))):
        if not os.path.isfile(os.path.join(render_dir, "RENDERED")):
            continue  # not (completely) rendered yet: train_sun_cnn.sh writes RENDERED last
        scenario = os.path.basename(render_dir)
        split = scenario.split("_", 1)[0]  # train, val or test
        d = drive_dir(render_dir)
        label_file = os.path.join(d, "gt", "sun_cam0.csv")
        with open(label_file) as f:
            labels = list(csv.DictReader(f))
        if split == "train":
            train_labels.append(label_file)
        for line, lab in enumerate(labels, start=2):
            try:
                k = int(lab["frame"])
                s = [float(lab["sx"]), float(lab["sy"]), float(lab["sz"])]
            except (KeyError, TypeError, ValueError) as e:
                fail(f"{label_file} line {line}: bad field ({e})")
            for cam in ("image_02", "image_03"):
                img = os.path.join(d, cam, "data", f"{k:010d}.png")
                if not os.path.isfile(img):
                    fail(f"missing {img} (label line {line})")
                rel = os.path.relpath(img, renders)
                rows.append([split, scenario, rel] + [f"{v:.6f}" for v in s])
                if split == "train":
                    train_images.append(img)
    return rows, train_images, train_labels


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--renders", help="folder of the train_*/val_*/test_* renders (optional)")
    ap.add_argument("--real", action="append", default=[], metavar="DIR:CSV[:SPLIT]",
                    help="a real KITTI folder and its sun file; SPLIT train, val or test "
                         "(default test); repeatable")
    ap.add_argument("--out", required=True, help="the manifest CSV to write")
    a = ap.parse_args()
    if not a.renders and not a.real:
        fail("give --renders DIR and/or --real DIR:CSV[:SPLIT]")
    rows, train_images, train_labels = [], [], []
    if a.renders:
        rows, train_images, train_labels = render_rows(a.renders)
    real_hashed, real_labels = [], []
    for text in a.real:
        folder, sun_csv, split = parse_real(text)
        r, hashed = real_rows(folder, sun_csv, split)
        rows += r
        real_hashed += hashed
        if split == "train":
            name = os.path.basename(os.path.normpath(os.path.abspath(folder)))
            real_labels.append((f"real_{name}/{os.path.basename(sun_csv)}", sun_csv))
    if not rows:
        fail(f"no train_*/val_*/test_* renders under {a.renders} and no --real folder")
    h = hashlib.sha256()
    for path in sorted(train_images) + sorted(train_labels):
        h.update(os.path.relpath(path, a.renders).encode() + b"\0")
        with open(path, "rb") as f:
            h.update(f.read())
    for key, path in sorted(real_hashed) + sorted(real_labels):
        h.update(key.encode() + b"\0")
        with open(path, "rb") as f:
            h.update(f.read())
    with open(a.out, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["split", "scenario", "image", "sx", "sy", "sz"])
        w.writerows(rows)
    with open(a.out + ".sha256", "w") as f:
        f.write(h.hexdigest() + "\n")
    counts = {s: sum(r[0] == s for r in rows) for s in SPLITS}
    print(f"sun_cnn_manifest: {counts['train']} training, {counts['val']} validation, "
          f"{counts['test']} test images; training data SHA-256 {h.hexdigest()}",
          file=sys.stderr)


if __name__ == "__main__":
    main()
