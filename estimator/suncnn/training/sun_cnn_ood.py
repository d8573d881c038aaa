#!/usr/bin/env python3
"""Does the distance of an image's features from the training images' flag Sun-CNN's gross
errors? (docs/sun_cnn_calibration.md, "Distance from the training features").

The ensemble's spread misses errors the members agree on; a look the network never saw can give
such errors. The textbook signal for it is how far the image's features lie from the training
images' (a Gaussian fitted to them, the Mahalanobis distance; Lee et al. 2018). This tool
measures it on a manifest that holds training rows (the Gaussian is fitted on them), val rows
(where a weight is chosen) and test rows (reported only), through OpenCV's DNN as in C++:

  trunk     per member, the trunk's 768 features (dropout off); d = sun_cnn_model's
            feature_distance (top 16 principal axes, whitened; about 1 on training images);
  fc1       the same on the head's first layer before its ReLU (128 values);
  shrunk    the trunk's features in the whole space, covariance shrunk 10 % towards its mean
            variance, divided by 768.

Prints d per split (train / val / test / each real folder); the AUC for gross (> 45 deg) vs not of
the spread, of d (large = gross: an out-of-distribution score) and of -d (small = gross: weak
features), over all frames and over the half with the smaller spread; then, per signal and form,
the validation calibration (sun_cnn_model.calibrate per elevation band, with the model JSON's
elevation gain) of raw' = sqrt(raw^2 + gain tan^2(e) + k term) for k in FEATURE_GAINS, applied
to test, with term = max(0, d - 1) ("far") or max(0, -ln d) ("weak", the shipped form).

    sun_cnn_ood.py --manifest M --model config/sun_cnn.onnx [--grey] [--out table.md]
"""
import argparse
import json
import os
import sys

import cv2
import numpy as np

from sun_cnn_calibrate import run_model
from sun_cnn_model import (FEATURE_GAINS, calibrate, combine, elevation_tan2, feature_distance,
                           feature_weakness, fit_feature_prior, member_layers, sigma_of,
                           trunk_layers)
from sun_cnn_signals import auc, emit, pct
from sun_cnn_train import labelled, load, signed_deg

SHRINK = 0.1


def fc1_layers(net):
    return member_layers(net, lambda n: n.startswith("onnx_node!/fc1") and n.endswith("Gemm"))


def shrunk_distance(train, feats):
    """Squared Mahalanobis distance / F in the whole space, per member, averaged over members."""
    d = np.zeros(feats.shape[1])
    for m in range(train.shape[0]):
        mu = train[m].mean(0)
        c = np.cov((train[m] - mu).T)
        p = c.shape[0]
        inv = np.linalg.inv((1 - SHRINK) * c + SHRINK * np.trace(c) / p * np.eye(p))
        x = feats[m] - mu
        d += np.einsum("ij,jk,ik->i", x, inv, x) / p
    return d / train.shape[0]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--manifest", required=True)
    ap.add_argument("--model", required=True)
    ap.add_argument("--grey", action="store_true", help="feed every image as a grey camera")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", help="also write the tables (markdown) here")
    a = ap.parse_args()
    cv2.setNumThreads(1)
    with open(os.path.splitext(a.model)[0] + ".json") as f:
        meta = json.load(f)
    gain = meta.get("gray_input", {}).get("elevation_gain", 0.0) if a.grey else \
        meta.get("elevation_gain", 0.0)
    net = cv2.dnn.readNetFromONNX(a.model)
    members = meta["mc"]["members"]
    layers = fc1_layers(net) + trunk_layers(net)
    if len(layers) != 2 * members:
        raise SystemExit(f"{a.model}: {len(layers)} fc1 and trunk layers for {members} members")
    data = load(a.manifest)
    rng = np.random.default_rng(a.seed)
    per = {}
    for split in ("train", "val", "test"):
        x, t, scen, sun = labelled(data, split, a.manifest, a.grey)
        dets, samps, extra = run_model(net, meta, x, rng, layers=layers)
        v, raw = combine(dets, samps)
        per[split] = dict(err=np.abs(signed_deg(v, t)), raw=raw, scen=scen, fc1=np.stack(extra[:members]),
                          trunk=np.stack(extra[members:]), tan2=elevation_tan2(sun))
        print(f"{split}: {len(t)} images", file=sys.stderr)

    priors = {k: fit_feature_prior(per["train"][k]) for k in ("trunk", "fc1")}
    for p in per.values():
        p["d"] = {"trunk": feature_distance(priors["trunk"], p["trunk"]),
                  "fc1": feature_distance(priors["fc1"], p["fc1"]),
                  "shrunk": shrunk_distance(per["train"]["trunk"], p["trunk"])}
    signals = list(per["val"]["d"])

    lines = ["| split / set | images | gross | " + " | ".join(f"d {k}: median (p90)" for k in signals)
             + " |", "| --- | ---: | ---: |" + " ---: |" * len(signals)]
    for split in ("train", "val", "test"):
        p = per[split]
        groups = [(split, np.ones(len(p["err"]), bool))]
        if split == "test":
            groups += [(s, p["scen"] == s) for s in sorted(set(p["scen"])) if s.startswith("real_")]
        for name, m in groups:
            cells = [f"{np.median(p['d'][k][m]):.2f} ({np.percentile(p['d'][k][m], 90):.2f})"
                     for k in signals]
            lines.append(f"| {name} | {m.sum()} | {pct(np.mean(p['err'][m] > 45))} | "
                         + " | ".join(cells) + " |")
    lines += ["", "| split, frames | AUC spread | " + " | ".join(f"AUC d {k} | AUC -d {k}" for k in signals)
              + " |", "| --- | ---: |" + " ---: | ---: |" * len(signals)]
    for split in ("val", "test"):
        p = per[split]
        for name, m in (("all", np.ones(len(p["err"]), bool)),
                        ("smaller-spread half", p["raw"] < np.median(p["raw"]))):
            bad = p["err"][m] > 45
            cells = [f"{auc(p['d'][k][m], bad):.3f} | {auc(-p['d'][k][m], bad):.3f}"
                     for k in signals]
            lines.append(f"| {split}, {name} | {auc(p['raw'][m], bad):.3f} | " + " | ".join(cells)
                         + " |")
    lines += ["", "| signal | form | k | val valid | val flagged | test valid | test flagged | "
              "test gross among valid | test within 2 sigma |",
              "| --- | --- | ---: | ---: | ---: | ---: | ---: | ---: | ---: |"]
    forms = {"far": lambda d: np.maximum(d - 1.0, 0.0), "weak": feature_weakness}
    for sig in signals:
        for form, term in forms.items():
            for k in FEATURE_GAINS:
                def raw_of(p):
                    return np.sqrt(p["raw"] ** 2 + gain * p["tan2"] + k * term(p["d"][sig]))
                v = per["val"]
                scale, thr = calibrate(v["err"], raw_of(v), v["tan2"])
                cells = []
                for split in ("val", "test"):
                    p = per[split]
                    sigma = sigma_of(raw_of(p), scale)
                    valid, bad = sigma <= thr, p["err"] > 45
                    cells += [pct(valid.mean()), pct(np.mean(~valid[bad])) if bad.any() else "–"]
                cells += [pct(np.mean(bad[valid])) if valid.any() else "–",
                          pct(np.mean(p["err"][valid] < 2 * np.degrees(sigma[valid])))
                          if valid.any() else "–"]
                lines.append(f"| {sig} | {form} | {k} | " + " | ".join(cells) + " |")
    table = "\n".join(lines)
    emit(table, a.out)


if __name__ == "__main__":
    main()
