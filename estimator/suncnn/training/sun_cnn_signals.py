#!/usr/bin/env python3
"""Which signal flags Sun-CNN's gross errors? Its own spread, test-time views of the image, or the
sun's elevation (docs/sun_cnn_calibration.md, "Uncertainty signals").

Runs an exported model through OpenCV's DNN (as the C++ estimator does) on every validation and
test image of a manifest, and on test-time views of it:
  flip   the image mirrored left-right; its answer mirrored back (az -> -az);
  gamma  the image with gamma 0.6 and 1.6 (brightness curve changed, geometry the same).
For each view set, the disagreement with the plain answer becomes a spread term,
sigma_view = sqrt(-2 ln R_view), R_view = the mean resultant length of the plain answer and the
views' answers, and the raw sigma becomes sqrt(raw^2 + k sigma_view^2). For every k the rule of
sun_cnn_calibrate.py (threshold flags 90 % of the validation gross errors, scale puts 95 % of the
valid validation frames within 2 sigma) is applied on the validation rows; the test rows are
scored with the validation's numbers (reported only). The answer itself stays the plain image's.

Then a ranking table (AUC of each signal for gross vs not, per split) and, per sun-elevation band,
three calibrations: the spread alone with the aggregate rule, the spread alone with the per-band
rule, and the spread plus the elevation term (sun_cnn_model.calibrate_elevation; what ships).

    sun_cnn_signals.py --manifest M --model config/sun_cnn.onnx [--grey] [--out table.md]
"""
import argparse
import json
import os
import sys

import cv2
import numpy as np

from sun_cnn_calibrate import run_model
from sun_cnn_model import (ELEVATION_BANDS_DEG, calibrate, calibrate_elevation, combine,
                           elevation_band, elevation_tan2, sigma_of, with_elevation)
from sun_cnn_train import labelled, load, report, signed_deg

KS = (0.0, 0.25, 0.5, 1.0, 2.0, 4.0)
NAN = float("nan")


def mirrored(v):
    return np.stack([v[:, 0], -v[:, 1]], 1)


def gamma(images, g):
    lut = np.clip(np.rint(255.0 * (np.arange(256) / 255.0) ** g), 0, 255).astype(np.uint8)
    return np.stack([cv2.LUT(im, lut) for im in images])


def unit(v):
    return v / np.maximum(np.linalg.norm(v, axis=1, keepdims=True), 1e-9)


def view_sigma(v, views):
    """sqrt(-2 ln R) of the plain answer's direction and the views' directions."""
    r = np.linalg.norm(np.mean([unit(v)] + [unit(w) for w in views], axis=0), axis=1)
    return np.sqrt(-2 * np.log(np.clip(r, 1e-6, 1.0)))


def auc(score, bad):
    """Probability that a gross frame scores higher than a good one (Mann-Whitney; 0.5 = chance)."""
    order = np.argsort(score, kind="stable")
    ranks = np.empty(len(score))
    ranks[order] = np.arange(1, len(score) + 1)
    nb, ng = bad.sum(), (~bad).sum()
    if nb == 0 or ng == 0:
        return NAN
    return float((ranks[bad].sum() - nb * (nb + 1) / 2) / (nb * ng))


def emit(table, out):
    """Prints a study tool's tables and, given a path, writes them there too (markdown)."""
    print(table)
    if out:
        with open(out, "w") as f:
            f.write(table + "\n")


def pct(x):
    return f"{100 * x:.0f} %" if np.isfinite(x) else "–"


def view_rows(per):
    rows = ["| view | k | val valid | val median (valid) | val gross flagged | val 2σ | "
            "test valid | test median (valid) | test gross (valid) | test gross flagged | "
            "test 2σ |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for view in ("flip", "gamma", "both"):
        for k in KS:
            if k == 0 and view != "flip":
                continue
            raws = {s: np.sqrt(p["raw"] ** 2 + k * p[view] ** 2) for s, p in per.items()}
            scale, thr = calibrate(per["val"]["err"], raws["val"])
            mv, mt = (report(per[s]["err"], raws[s], per[s]["scen"], scale, thr)["all"]
                      for s in ("val", "test"))
            rows.append(
                f"| {'plain' if k == 0 else view} | {k:g} | {pct(mv['valid_share'])} | "
                f"{mv.get('valid_median_deg', NAN):.1f}° | "
                f"{pct(mv.get('gross_flagged_share', NAN))} | "
                f"{pct(mv.get('within_2sigma_share', NAN))} | {pct(mt['valid_share'])} | "
                f"{mt.get('valid_median_deg', NAN):.1f}° | "
                f"{100 * mt.get('valid_gross_share', NAN):.1f} % | "
                f"{pct(mt.get('gross_flagged_share', NAN))} | "
                f"{pct(mt.get('within_2sigma_share', NAN))} |")
    return rows


def ranking_rows(per):
    rows = ["| set | gross share | AUC raw | AUC flip | AUC gamma | AUC both | AUC elevation | "
            "corr(raw, flip) | median plain / flip-averaged | gross plain / flip-averaged |",
            "| --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"]
    for s, p in per.items():
        bad = np.abs(p["err"]) > 45
        rows.append(f"| {s} | {100 * bad.mean():.1f} % | " +
                    " | ".join(f"{auc(p[k], bad):.3f}" for k in ("raw", "flip", "gamma", "both",
                                                                 "tan2")) +
                    f" | {np.corrcoef(p['raw'], p['flip'])[0, 1]:.2f} | "
                    f"{np.median(np.abs(p['err'])):.1f}° / "
                    f"{np.median(np.abs(p['err_avg'])):.1f}° | "
                    f"{100 * bad.mean():.1f} / {100 * (np.abs(p['err_avg']) > 45).mean():.1f} % |")
    return rows


def band_rows(per):
    """Valid share, gross flagged and 2-sigma share per elevation band, for three calibrations
    chosen on the validation rows."""
    v = per["val"]
    gain, e_scale, e_thr = calibrate_elevation(v["err"], v["raw"], v["tan2"])
    rules = [("spread, aggregate rule", 0.0, *calibrate(v["err"], v["raw"])),
             ("spread, per-band rule", 0.0, *calibrate(v["err"], v["raw"], v["tan2"])),
             (f"spread + elevation (gain {gain:g}), per-band rule", gain, e_scale, e_thr)]
    edges = ELEVATION_BANDS_DEG
    head = " | ".join(f"{edges[b]:g}–{edges[b + 1]:g}°" for b in range(len(edges) - 1))
    rows = [f"| set | calibration | all | {head} |",
            "| --- | --- | --- |" + " --- |" * (len(edges) - 1)]
    for s, p in per.items():
        band = elevation_band(p["tan2"])
        err = np.abs(p["err"])
        for name, g, scale, thr in rules:
            sigma = sigma_of(with_elevation(p["raw"], p["tan2"], g), scale)
            valid = sigma <= thr

            def cell(m):
                if m.sum() == 0:
                    return "–"
                gross, vm = m & (err > 45), m & valid
                flagged = np.mean(~valid[gross]) if gross.sum() else NAN
                within = np.mean(np.radians(err[vm]) < 2 * sigma[vm]) if vm.sum() else NAN
                return (f"{m.sum()}: valid {pct(vm.sum() / m.sum())}, flagged {pct(flagged)} of "
                        f"{gross.sum()}, 2σ {pct(within)}")

            cells = [cell(np.ones_like(valid))] + [cell(band == b) for b in range(len(edges) - 1)]
            rows.append(f"| {s} | {name} (scale {scale:.4f}, threshold {thr:.4f}) | " +
                        " | ".join(cells) + " |")
    return rows


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--manifest", required=True)
    ap.add_argument("--model", required=True)
    ap.add_argument("--grey", action="store_true",
                    help="feed the images as a grey camera, (Y, Y, Y)")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", help="also write the tables (markdown) here")
    a = ap.parse_args()
    cv2.setNumThreads(1)
    with open(os.path.splitext(a.model)[0] + ".json") as f:
        meta = json.load(f)
    net = cv2.dnn.readNetFromONNX(a.model)
    data = load(a.manifest)
    rng = np.random.default_rng(a.seed)
    per = {}
    for split in ("val", "test"):
        x, t, scen, sun = labelled(data, split, a.manifest, a.grey)
        v, raw = combine(*run_model(net, meta, x, rng))
        flip = mirrored(run_model(net, meta, x[:, :, ::-1].copy(), rng)[0].mean(0))
        g_lo = run_model(net, meta, gamma(x, 0.6), rng)[0].mean(0)
        g_hi = run_model(net, meta, gamma(x, 1.6), rng)[0].mean(0)
        avg = unit(v) + unit(flip)  # the plain and the mirrored-back answer averaged
        per[split] = dict(err=signed_deg(v, t), raw=raw, scen=scen, err_avg=signed_deg(avg, t),
                          flip=view_sigma(v, [flip]), gamma=view_sigma(v, [g_lo, g_hi]),
                          both=view_sigma(v, [flip, g_lo, g_hi]), tan2=elevation_tan2(sun))
        print(f"{split}: {len(t)} images", file=sys.stderr)

    table = "\n".join(view_rows(per) + [""] + ranking_rows(per) + [""] + band_rows(per))
    emit(table, a.out)


if __name__ == "__main__":
    main()
