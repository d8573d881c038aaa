#!/usr/bin/env python3
"""Lists the rendered Sun-CNN frames with their labels and hashes the training data.

For every completely rendered folder <renders>/{train,val,test}_*/ (one sunvo_render drive each,
marked by the file RENDERED) it reads
gt/sun_cam0.csv and lists the colour images of both cameras (image_02, image_03: same
orientation, so the same sun vector in the camera frame). Writes a CSV manifest
    split,scenario,image,sx,sy,sz
(image relative to <renders>) and <out>.sha256: the SHA-256 over the training split, i.e. over
the sorted (relative path, file bytes) of every train_* image followed by every train_* label file
(gt/sun_cam0.csv) in sorted order.
"""
import argparse
import csv
import glob
import hashlib
import os
import sys


def drive_dir(render_dir):
    found = sorted(glob.glob(os.path.join(render_dir, "*", "*_sync")))
    if len(found) != 1:
        raise SystemExit(f"sun_cnn_manifest: {render_dir}: expected one *_sync drive, found {len(found)}")
    return found[0]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--renders", required=True)
    ap.add_argument("--out", required=True)
    a = ap.parse_args()
    rows = []
    train_images, train_labels = [], []
    for render_dir in sorted(glob.glob(os.path.join(a.renders, "train_*")) +
                             glob.glob(os.path.join(a.renders, "val_*")) +
                             glob.glob(os.path.join(a.renders, "test_*"))):
        if not os.path.isfile(os.path.join(render_dir, "RENDERED")):
            continue  # not (completely) rendered yet: train_sun_cnn.sh writes RENDERED last
        scenario = os.path.basename(render_dir)
        split = scenario.split("_", 1)[0]  # train, val (choices) or test (reported only)
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
            except (KeyError, ValueError) as e:
                raise SystemExit(f"sun_cnn_manifest: {label_file} line {line}: bad field ({e})")
            for cam in ("image_02", "image_03"):
                img = os.path.join(d, cam, "data", f"{k:010d}.png")
                if not os.path.isfile(img):
                    raise SystemExit(f"sun_cnn_manifest: missing {img} (label line {line})")
                rel = os.path.relpath(img, a.renders)
                rows.append([split, scenario, rel] + [f"{v:.6f}" for v in s])
                if split == "train":
                    train_images.append(img)
    if not rows:
        raise SystemExit(f"sun_cnn_manifest: no train_*/val_*/test_* renders under {a.renders}")
    h = hashlib.sha256()
    for path in sorted(train_images) + sorted(train_labels):
        h.update(os.path.relpath(path, a.renders).encode() + b"\0")
        with open(path, "rb") as f:
            h.update(f.read())
    with open(a.out, "w", newline="") as f:
        w = csv.writer(f)
        w.writerow(["split", "scenario", "image", "sx", "sy", "sz"])
        w.writerows(rows)
    with open(a.out + ".sha256", "w") as f:
        f.write(h.hexdigest() + "\n")
    n_train = sum(r[0] == "train" for r in rows)
    print(f"sun_cnn_manifest: {n_train} training, {len(rows) - n_train} validation/test images; "
          f"training data SHA-256 {h.hexdigest()}", file=sys.stderr)


if __name__ == "__main__":
    main()
