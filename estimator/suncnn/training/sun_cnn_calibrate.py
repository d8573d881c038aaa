#!/usr/bin/env python3
"""Re-chooses an exported Sun-CNN's validity threshold and sigma scale on the manifest's
validation rows, without retraining, and rewrites the model's JSON (elevation_gain, feature_gain,
feature_prior, sigma_scale, max_valid_sigma_rad, results per split;
sun_cnn_model.calibrate_elevation, calibrate_features). The feature term needs training rows in
the manifest (its prior is fitted on them); without them it is off (feature_gain 0). The model runs
through OpenCV's DNN, as in C++: image -> INTER_AREA resize -> planes -> 16 MC mask rows per
member (numpy masks).

    sun_cnn_calibrate.py --manifest /work/renders/sun_cnn_manifest.csv --model config/sun_cnn.onnx

A colour model gets a second calibration, "gray_input": the same choice for the validation
images as a grey camera gives them to it, (Y, Y, Y) (--grey-only: that one alone). Splits the
manifest does not list keep their old scores under "results_previous_calibration".
"""
import argparse
import json
import os
import re
import sys

import cv2
import numpy as np

from sun_cnn_model import (DROPOUT_P, FEATURE_PCS, IN_H, IN_W, MEAN, STD, calibrate_elevation,
                           calibrate_features, combine, elevation_tan2, feature_distance,
                           feature_prior_json, feature_weakness, fit_feature_prior, trunk_layers,
                           with_elevation)
from sun_cnn_train import LUMA, labelled, load, report, signed_deg

SAMPLES = 16
MIN_TRAIN_FOR_PRIOR = 4 * FEATURE_PCS  # training images, else no feature term


def run_model(net, meta, images, rng, grey_in=False, layers=()):
    """[M, n, 2] deterministic outputs and [M, n, S, 2] MC samples of the ONNX model; grey_in:
    the images as a grey camera gives them to a colour model, (Y, Y, Y). With layers (names of
    layers, e.g. trunk_layers(net)), also a list of their outputs for the deterministic row, one
    [n, size] array per layer (a trunk's single row is its own)."""
    ch, members = meta["input"]["channels"], meta["mc"]["members"]
    rows, f, d = meta["mc"]["rows"], meta["mc"]["mask1"], meta["mc"]["mask2"]
    keep = 1.0 / (1.0 - DROPOUT_P)
    dets = np.zeros((members, len(images), 2), np.float32)
    samps = np.zeros((members, len(images), SAMPLES, 2), np.float32)
    extra = None
    for i, img in enumerate(images):
        small = cv2.resize(img, (IN_W, IN_H), interpolation=cv2.INTER_AREA).astype(np.float32)
        if ch == 1:
            small = (small @ LUMA)[..., None]
        elif grey_in:
            small = np.repeat((small @ LUMA)[..., None], 3, axis=-1)
        blob = ((small / 255.0 - MEAN) / STD).transpose(2, 0, 1)[None].copy()
        m1 = np.ones((rows, f), np.float32)
        m2 = np.ones((rows, d), np.float32)
        m1[1:SAMPLES + 1] = (rng.random((SAMPLES, f)) >= DROPOUT_P) * keep
        m2[1:SAMPLES + 1] = (rng.random((SAMPLES, d)) >= DROPOUT_P) * keep
        net.setInput(blob, "image")
        net.setInput(m1, "mask1")
        net.setInput(m2, "mask2")
        outs = net.forward(["azimuth_cs"] + list(layers))
        out = outs[0].reshape(members, rows, 2)
        dets[:, i] = out[:, 0]
        samps[:, i] = out[:, 1:SAMPLES + 1]
        if layers:
            rows0 = [o.reshape(o.shape[0], -1)[0] for o in outs[1:]]
            if extra is None:
                extra = [np.zeros((len(images), r.size), np.float32) for r in rows0]
            for j, r in enumerate(rows0):
                extra[j][i] = r
    return (dets, samps, extra) if layers else (dets, samps)


def dumps(meta):
    """JSON with an indent of 2 and every list of numbers on one line (the feature prior's)."""
    text = json.dumps(meta, indent=2)
    return re.sub(r"\[\s+([-+0-9.eE,\s]+?)\s+\]",
                  lambda m: "[" + ", ".join(x.strip() for x in m.group(1).split(",")) + "]", text)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--manifest", required=True)
    ap.add_argument("--model", required=True)
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--grey-only", action="store_true",
                    help="a colour model: choose only the grey-input numbers, keep the colour ones")
    a = ap.parse_args()
    cv2.setNumThreads(1)
    json_path = os.path.splitext(a.model)[0] + ".json"
    with open(json_path) as f:
        meta = json.load(f)
    net = cv2.dnn.readNetFromONNX(a.model)
    data = load(a.manifest)
    rng = np.random.default_rng(a.seed)
    if "val" not in data:
        raise SystemExit(f"{a.manifest}: no validation rows to calibrate on")

    layers = trunk_layers(net)

    def calibrated(grey_in, splits, rng):
        evals = {}
        for split in splits:
            x, t, scen, sun = labelled(data, split, a.manifest)
            dets, samps, trunk = run_model(net, meta, x, rng, grey_in, layers)
            trunk = np.stack(trunk)  # [M, n, F]
            v, raw = combine(dets, samps)
            evals[split] = (signed_deg(v, t), raw, scen, elevation_tan2(sun), trunk)
        val_err, val_raw, _, val_tan2, _ = evals["val"]
        gain, scale, threshold = calibrate_elevation(val_err, val_raw, val_tan2)
        weak = {k: np.zeros(len(e[0])) for k, e in evals.items()}
        feature = {"feature_gain": 0.0}
        if "train" in evals and len(evals["train"][0]) >= MIN_TRAIN_FOR_PRIOR:
            # The feature term needs enough training images to fit their features' Gaussian.
            prior = fit_feature_prior(evals["train"][4])
            weak = {k: feature_weakness(feature_distance(prior, e[4])) for k, e in evals.items()}
            f_gain, scale, threshold = calibrate_features(
                val_err, with_elevation(val_raw, val_tan2, gain), val_tan2, weak["val"])
            feature = {"feature_gain": f_gain}
            if f_gain > 0:  # a prior that weighs nothing is not shipped
                feature["feature_prior"] = feature_prior_json(prior)
        return gain, scale, threshold, feature, {
            k: report(e, np.sqrt(with_elevation(r, t2, gain) ** 2 +
                                 feature["feature_gain"] * weak[k]), s, scale, threshold)
            for k, (e, r, s, t2, _) in evals.items()}

    if a.grey_only and meta["input"]["channels"] != 3:
        raise SystemExit(f"{a.model}: --grey-only needs a colour model")
    if not a.grey_only:
        # Validation first: the masks it draws do not depend on the other rows listed.
        gain, scale, threshold, feature, scored = calibrated(
            False, ["val"] + [k for k in data if k != "val"], rng)
        meta["sigma_scale"], meta["max_valid_sigma_rad"] = scale, threshold
        meta["elevation_gain"] = gain
        meta.pop("feature_prior", None)
        meta.update(feature)
        # A split the manifest does not list (e.g. the training renders, not at hand) keeps its
        # old scores, under a name that says they belong to the previous calibration.
        old = {**meta.pop("results_previous_calibration", {}), **meta.get("results", {})}
        old = {k: v for k, v in old.items() if k not in scored}
        meta["results"] = scored
        if old:
            meta["results_previous_calibration"] = old
    if meta["input"]["channels"] == 3:
        # Grey cameras fed to this colour model as (Y, Y, Y): their own threshold and scale, with
        # masks of their own, validation first (the same whatever other rows the manifest lists).
        g_gain, g_scale, g_threshold, g_feature, g_results = calibrated(
            True, ["val"] + [k for k in data if k != "val"], np.random.default_rng([a.seed, 1]))
        meta["gray_input"] = {"sigma_scale": g_scale, "max_valid_sigma_rad": g_threshold,
                              "elevation_gain": g_gain, **g_feature, "results": g_results}
    meta["calibration"] = ("sun_cnn_calibrate.py: raw' = sqrt(raw^2 + elevation_gain tan^2(sun "
                           "elevation) + feature_gain max(0, -ln d)), d the trunk features' "
                           "distance from the training images' (feature_prior, fitted on the "
                           "manifest's training rows; none without them), each gain leaving the "
                           "most validation frames valid; "
                           "threshold flags 90 % of the validation gross errors in every elevation "
                           "band holding >= 10 of them; scale puts 95 % of the valid validation "
                           "frames within 2 sigma")
    with open(json_path, "w") as f:
        f.write(dumps(meta) + "\n")
    for split, r in list(meta["results"].items()) + [
            ("grey " + k, v) for k, v in meta.get("gray_input", {}).get("results", {}).items()]:
        m = r["all"]
        print(f"{split}: median {m['median_deg']:.1f} deg, gross {100 * m['gross_share']:.1f} %, "
              f"valid {100 * m['valid_share']:.0f} %, gross flagged "
              f"{100 * m.get('gross_flagged_share', float('nan')):.0f} %, within 2 sigma "
              f"{100 * m.get('within_2sigma_share', float('nan')):.0f} %", file=sys.stderr)
    print(f"{json_path}: elevation_gain {meta.get('elevation_gain', 0.0):g}, feature_gain "
          f"{meta.get('feature_gain', 0.0):g}, sigma_scale "
          f"{meta['sigma_scale']:.4f}, max_valid_sigma_rad {meta['max_valid_sigma_rad']:.4f}",
          file=sys.stderr)
    if "gray_input" in meta:
        g = meta["gray_input"]
        print(f"{json_path}: grey input: elevation_gain {g['elevation_gain']:g}, feature_gain "
              f"{g.get('feature_gain', 0.0):g}, sigma_scale "
              f"{g['sigma_scale']:.4f}, max_valid_sigma_rad "
              f"{g['max_valid_sigma_rad']:.4f}", file=sys.stderr)


if __name__ == "__main__":
    main()
