#!/usr/bin/env python3
"""Re-chooses an exported Sun-CNN's validity threshold and sigma scale on the manifest's
validation rows, without retraining, and rewrites the model's JSON (sigma_scale,
max_valid_sigma_rad, results per split). The model runs through OpenCV's DNN, as in C++:
image -> INTER_AREA resize -> planes -> 16 MC mask rows per member (numpy masks).

    sun_cnn_calibrate.py --manifest /work/renders/sun_cnn_manifest.csv --model config/sun_cnn.onnx
"""
import argparse
import json
import os
import sys

import cv2
import numpy as np

from sun_cnn_model import DROPOUT_P, IN_H, IN_W, MEAN, STD, calibrate, combine
from sun_cnn_train import LUMA, load, report, signed_deg, targets

SAMPLES = 16


def run_model(net, meta, images, rng):
    """[M, n, 2] deterministic outputs and [M, n, S, 2] MC samples of the ONNX model."""
    ch, members = meta["input"]["channels"], meta["mc"]["members"]
    rows, f, d = meta["mc"]["rows"], meta["mc"]["mask1"], meta["mc"]["mask2"]
    keep = 1.0 / (1.0 - DROPOUT_P)
    dets = np.zeros((members, len(images), 2), np.float32)
    samps = np.zeros((members, len(images), SAMPLES, 2), np.float32)
    for i, img in enumerate(images):
        small = cv2.resize(img, (IN_W, IN_H), interpolation=cv2.INTER_AREA).astype(np.float32)
        if ch == 1:
            small = (small @ LUMA)[..., None]
        blob = ((small / 255.0 - MEAN) / STD).transpose(2, 0, 1)[None].copy()
        m1 = np.ones((rows, f), np.float32)
        m2 = np.ones((rows, d), np.float32)
        m1[1:SAMPLES + 1] = (rng.random((SAMPLES, f)) >= DROPOUT_P) * keep
        m2[1:SAMPLES + 1] = (rng.random((SAMPLES, d)) >= DROPOUT_P) * keep
        net.setInput(blob, "image")
        net.setInput(m1, "mask1")
        net.setInput(m2, "mask2")
        out = net.forward("azimuth_cs").reshape(members, rows, 2)
        dets[:, i] = out[:, 0]
        samps[:, i] = out[:, 1:SAMPLES + 1]
    return dets, samps


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--manifest", required=True)
    ap.add_argument("--model", required=True)
    ap.add_argument("--seed", type=int, default=1)
    a = ap.parse_args()
    cv2.setNumThreads(1)
    json_path = os.path.splitext(a.model)[0] + ".json"
    with open(json_path) as f:
        meta = json.load(f)
    net = cv2.dnn.readNetFromONNX(a.model)
    data = load(a.manifest)
    rng = np.random.default_rng(a.seed)
    evals = {}
    for split, (x, sun, scen) in data.items():
        t, w = targets(sun)
        keep = w > 0
        v, raw = combine(*run_model(net, meta, x[keep], rng))
        evals[split] = (signed_deg(v, t[keep]), raw, np.array(scen)[keep])
    if "val" not in evals:
        raise SystemExit(f"{a.manifest}: no validation rows to calibrate on")
    scale, threshold = calibrate(evals["val"][0], evals["val"][1])
    meta["sigma_scale"], meta["max_valid_sigma_rad"] = scale, threshold
    meta["results"] = {k: report(e, r, s, scale, threshold) for k, (e, r, s) in evals.items()}
    meta["calibration"] = ("sun_cnn_calibrate.py: threshold flags 90 % of the validation gross "
                           "errors; scale puts 95 % of the valid validation frames within 2 sigma")
    with open(json_path, "w") as f:
        json.dump(meta, f, indent=2)
        f.write("\n")
    for split, r in meta["results"].items():
        m = r["all"]
        print(f"{split}: median {m['median_deg']:.1f} deg, gross {100 * m['gross_share']:.1f} %, "
              f"valid {100 * m['valid_share']:.0f} %, gross flagged "
              f"{100 * m.get('gross_flagged_share', float('nan')):.0f} %, within 2 sigma "
              f"{100 * m.get('within_2sigma_share', float('nan')):.0f} %", file=sys.stderr)
    print(f"{json_path}: sigma_scale {scale:.4f}, max_valid_sigma_rad {threshold:.4f}",
          file=sys.stderr)


if __name__ == "__main__":
    main()
