#!/usr/bin/env python3
"""Do the colour and the grey model answer better together? (docs/sun_cnn_calibration.md, "Both
models as one ensemble").

Two models ship, each a deep ensemble of three members trained on the same renders from the same
seeds, each on its own input (BGR, grey). Where their errors are partly independent, their six
members together are a larger ensemble: the answer is the direction of the mean of the six
deterministic vectors, and the raw spread (sun_cnn_model.combine) counts the six members' MC
samples and the mean's shortness, which grows where the two models disagree.

For one camera (--camera colour: the colour model sees BGR; grey: it sees (Y, Y, Y), as the
rover's grey V4L2 cameras give it; the grey model sees Y either way), rows:
  shipped        the colour model with its JSON's calibration for that camera (elevation and
                 feature terms, scale, threshold), as the C++ estimator runs it;
  colour / grey  one model, calibrated on the validation drives by the shipped rule
                 (sun_cnn_model.calibrate_elevation: the elevation gain, 90 % of the gross errors
                 flagged in every elevation band, 95 % of the valid within 2 sigma);
  both           the six members, the same rule;
  both + feature the six members and the colour model's feature term, its gain chosen on the
                 validation drives (sun_cnn_model.calibrate_features).
Every choice is made on the val rows; the test rows are scored with the validation's numbers
(reported only). CPU cost: both models per call, i.e. the sum of their times. A second table
says how independent the two models' errors are.

    sun_cnn_pair.py --manifest M --model config/sun_cnn.onnx [--grey-model G]
                    [--camera colour|grey] [--out table.md]
(G: the grey model, by default sun_cnn_gray.onnx beside the colour model.)
"""
import argparse
import json
import os
import sys

import cv2
import numpy as np

from sun_cnn_calibrate import run_model
from sun_cnn_model import (calibrate_elevation, calibrate_features, combine, elevation_tan2,
                           feature_distance, feature_prior_from_json, feature_weakness, sigma_of,
                           trunk_layers, with_elevation)
from sun_cnn_signals import auc, emit, pct
from sun_cnn_train import labelled, load, metrics, signed_deg


def read(model):
    with open(os.path.splitext(model)[0] + ".json") as f:
        return cv2.dnn.readNetFromONNX(model), json.load(f)


def columns(m):
    """One set's row cells from sun_cnn_train.metrics' dictionary and the AUC."""
    def deg(k):
        return f"{m[k]:.1f}°" if k in m else "–"

    def share(k):
        return pct(m[k]) if k in m else "–"
    return [deg("median_deg"), share("valid_share"), deg("valid_median_deg"),
            share("valid_gross_share"), share("gross_flagged_share"), share("within_2sigma_share"),
            deg("valid_signed_median_deg"), f"{m['auc']:.3f}"]


def scored(err, raw, tan2, gain, scale, threshold, extra=0.0):
    """metrics() of signed errors under a calibration, plus the AUC of raw' for gross errors and
    the signed median over the valid frames (the bias the fusion sees)."""
    r = np.sqrt(with_elevation(raw, tan2, gain) ** 2 + extra)
    sigma = sigma_of(r, scale)
    valid = sigma <= threshold
    m = metrics(err, sigma, valid)
    if valid.any():
        m["valid_signed_median_deg"] = float(np.median(err[valid]))
    m["auc"] = auc(r, np.abs(err) > 45)
    return m


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--manifest", required=True)
    ap.add_argument("--model", required=True, help="the colour model (.onnx, JSON beside it)")
    ap.add_argument("--grey-model", help="the grey model (default: sun_cnn_gray.onnx beside it)")
    ap.add_argument("--camera", choices=("colour", "grey"), default="colour")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", help="also write the table (markdown) here")
    a = ap.parse_args()
    cv2.setNumThreads(1)
    grey_model = a.grey_model or os.path.join(os.path.dirname(a.model), "sun_cnn_gray.onnx")
    net_c, meta_c = read(a.model)
    net_g, meta_g = read(grey_model)
    if meta_c["input"]["channels"] != 3 or meta_g["input"]["channels"] != 1:
        raise SystemExit(f"{a.model} must be a colour model and {grey_model} a grey one")
    grey_cam = a.camera == "grey"
    cal = meta_c.get("gray_input", meta_c) if grey_cam else meta_c
    prior = feature_prior_from_json(meta_c["feature_prior"]) if "feature_prior" in meta_c \
        else None
    data = load(a.manifest)
    rng = np.random.default_rng(a.seed)
    per = {}
    for split in ("val", "test"):
        x, t, scen, sun = labelled(data, split, a.manifest, grey_cam)
        dets_c, samps_c, trunk = run_model(net_c, meta_c, x, rng, layers=trunk_layers(net_c))
        dets_g, samps_g = run_model(net_g, meta_g, x, rng)
        weak = feature_weakness(feature_distance(prior, np.stack(trunk))) if prior else \
            np.zeros(len(t))
        runs = {"colour": combine(dets_c, samps_c), "grey": combine(dets_g, samps_g),
                "both": combine(np.concatenate([dets_c, dets_g]),
                                np.concatenate([samps_c, samps_g]))}
        per[split] = dict(tan2=elevation_tan2(sun), weak=weak,
                          err={k: signed_deg(v, t) for k, (v, _) in runs.items()},
                          raw={k: r for k, (_, r) in runs.items()})
        print(f"{split}: {len(t)} images", file=sys.stderr)

    val, test = per["val"], per["test"]
    rows = []
    # As shipped: the JSON's own numbers for this camera.
    ship = (cal.get("elevation_gain", 0.0), cal["sigma_scale"], cal["max_valid_sigma_rad"])
    f_ship = cal.get("feature_gain", 0.0)
    rows.append(("shipped (colour model, its JSON)", "colour", ship,
                 lambda s: f_ship * s["weak"]))
    for name in ("colour", "grey", "both"):
        rows.append((f"{name}, rule on val", name,
                     calibrate_elevation(np.abs(val["err"][name]), val["raw"][name], val["tan2"]),
                     lambda s: 0.0))
    g, _, _ = calibrate_elevation(np.abs(val["err"]["both"]), val["raw"]["both"], val["tan2"])
    fg, fs, ft = calibrate_features(np.abs(val["err"]["both"]),
                                    with_elevation(val["raw"]["both"], val["tan2"], g),
                                    val["tan2"], val["weak"])
    rows.append((f"both + colour's feature term (gain {fg:g}), rule on val", "both", (g, fs, ft),
                 lambda s, fg=fg: fg * s["weak"]))

    head = ["median (all)", "valid", "median (valid)", "gross among valid", "gross flagged",
            "within 2σ", "bias (valid)", "AUC"]
    lines = [f"camera: {a.camera}; val (calibrated on) | test (reported only)", "",
             "| run | elevation gain | " + " | ".join(f"val {h}" for h in head) + " | "
             + " | ".join(f"test {h}" for h in head) + " |",
             "| --- | ---: |" + " ---: |" * (2 * len(head))]
    for label, name, (gain, scale, threshold), extra in rows:
        cells = []
        for s in (val, test):
            cells += columns(scored(s["err"][name], s["raw"][name], s["tan2"], gain, scale,
                                    threshold, extra(s)))
        lines.append(f"| {label} | {gain:g} | " + " | ".join(cells) + " |")
    # How independent the two models' errors are (what an ensemble of them can gain).
    lines += ["", "| split | gross, colour | gross, grey | gross in both | colour's gross the grey "
              "model shares | corr. of signed errors (both < 45°) | grey nearer the truth |",
              "| --- | ---: | ---: | ---: | ---: | ---: | ---: |"]
    for split, s in per.items():
        ec, eg = s["err"]["colour"], s["err"]["grey"]
        gc, gg = np.abs(ec) > 45, np.abs(eg) > 45
        fine = ~gc & ~gg
        corr = np.corrcoef(ec[fine], eg[fine])[0, 1] if fine.sum() > 2 else float("nan")
        lines.append(f"| {split} | {pct(gc.mean())} | {pct(gg.mean())} | {pct((gc & gg).mean())} "
                     f"| {pct(np.mean(gg[gc])) if gc.any() else '–'} | {corr:.2f} | "
                     f"{pct(np.mean(np.abs(eg) < np.abs(ec)))} |")
    table = "\n".join(lines)
    emit(table, a.out)


if __name__ == "__main__":
    main()
