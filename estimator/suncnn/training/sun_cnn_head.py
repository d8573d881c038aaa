#!/usr/bin/env python3
"""Can a learned confidence head flag Sun-CNN's gross errors better than the hand-set sigma?
(docs/sun_cnn_calibration.md, "A learned confidence head").

The shipped sigma adds three signals with gains chosen on the validation drives:
    raw'^2 = raw^2 + elevation_gain tan^2(e) + feature_gain max(0, -ln d).
A head learns how much each per-image signal says about the error, in two forms:
  log-error   a ridge regression of ln(err^2 + (1 deg)^2) on the signals (a heteroscedastic fit:
              exp(pred / 2) is a sigma up to the scale the calibration chooses anyway);
  gross       a ridge logistic regression of "gross" (> 45 deg) on the signals; its probability,
              scaled, is the sigma (a ranking more than an error size).
Signals per image:
  ln(-2 ln R_mc), ln(-2 ln R_al)     the MC spread and the ensemble mean's shortness
  ln(-2 ln R_members)                the members' disagreement (their deterministic answers)
  ln(tan^2 e + 0.01)                 the sun's elevation (from the true sun here, the prior in C++)
  ln d                               the trunk features' distance (the JSON's feature_prior)
  z (--pcs)                          the trunk features' whitened principal coordinates, per
                                     member (the feature_prior's axes): what the trunk saw.
The head is fitted on the validation drives (they have the looks a deployment meets: none was
trained on), so its validation scores are **out of fold**: the drives are cut into FOLDS groups
(a manifest of one drive: its frames), each group scored by a head fitted on the others, and
sun_cnn_model.calibrate's rule (90 % of the gross errors flagged in every elevation band; 95 % of
the valid within 2 sigma; no clamp) runs on those scores.
The test rows are scored by the head fitted on all validation drives (reported only).

    sun_cnn_head.py --manifest M --model config/sun_cnn.onnx [--grey] [--out table.md]
"""
import argparse
import json
import os
import sys

import cv2
import numpy as np

from sun_cnn_calibrate import run_model
from sun_cnn_model import (combine, elevation_tan2, feature_distance, feature_prior_from_json,
                           feature_weakness, flag_threshold, trunk_layers)
from sun_cnn_signals import auc, emit, pct
from sun_cnn_train import labelled, load, signed_deg

FOLDS = 4
LAMBDAS = (0.1, 1.0, 10.0, 100.0)


def unit(v):
    return v / np.maximum(np.linalg.norm(v, axis=-1, keepdims=True), 1e-9)


def neg2ln(r):
    return -2 * np.log(np.clip(r, 1e-6, 1.0))


def signals(dets, samps, trunk, tan2, prior, pcs):
    """[n, k] per-image signals (see the module's text) and their names."""
    m, n, s, _ = samps.shape
    r_mc = np.linalg.norm(unit(samps).transpose(1, 0, 2, 3).reshape(n, m * s, 2).mean(1), axis=1)
    r_al = np.linalg.norm(dets.mean(0), axis=1)
    r_mem = np.linalg.norm(unit(dets).mean(0), axis=1)
    d = feature_distance(prior, trunk)
    cols = [np.log(neg2ln(r_mc) + 1e-6), np.log(neg2ln(r_al) + 1e-6),
            np.log(neg2ln(r_mem) + 1e-6), np.log(tan2 + 0.01), np.log(np.maximum(d, 1e-6))]
    names = ["ln mc", "ln al", "ln members", "ln tan2", "ln d"]
    for k in range(m):
        z = (trunk[k] - prior["mean"][k]) @ prior["axes"][k][:pcs].T
        cols += list((z / np.sqrt(prior["variances"][k][:pcs])).T)
        names += [f"z{k}.{j}" for j in range(pcs)]
    return np.stack(cols, 1), names


class Head:
    """Ridge regression of y on standardised x (the intercept unpenalised); logistic=True: ridge
    logistic regression of y in {0, 1} (Newton's method), returning log-odds."""

    def __init__(self, x, y, lam, logistic=False):
        self.mu, self.sd = x.mean(0), np.maximum(x.std(0), 1e-9)
        z = np.c_[np.ones(len(y)), (x - self.mu) / self.sd]
        pen = lam * len(y) / 100.0 * np.diag(np.r_[0.0, np.ones(x.shape[1])])
        if not logistic:
            self.w = np.linalg.solve(z.T @ z + pen, z.T @ y)
            return
        self.w = np.zeros(z.shape[1])
        if y.min() == y.max():  # one class: a constant log-odds (the penalty keeps w at 0)
            self.w[0] = np.log(np.clip(y.mean(), 1e-3, 1 - 1e-3) / np.clip(1 - y.mean(), 1e-3, 1))
            return
        for _ in range(30):
            p = 1.0 / (1.0 + np.exp(-np.clip(z @ self.w, -30, 30)))
            hess = (z * (p * (1 - p))[:, None]).T @ z + pen
            self.w -= np.linalg.solve(hess, z.T @ (p - y) + pen @ self.w)

    def __call__(self, x):
        return np.c_[np.ones(len(x)), (x - self.mu) / self.sd] @ self.w


def target(err_deg):
    return np.log(np.radians(err_deg) ** 2 + np.radians(1.0) ** 2)


def out_of_fold(x, y, scen, lam, logistic):
    """Each drive group's predictions from a head fitted on the other groups."""
    drives = sorted(set(scen))
    if len(drives) > 1:
        g = np.array([drives.index(s) % FOLDS for s in scen])
    else:
        g = np.arange(len(y)) % FOLDS
    pred = np.zeros(len(y))
    for k in np.unique(g):
        pred[g == k] = Head(x[g != k], y[g != k], lam, logistic)(x[g == k])
    return pred


def scores(err, raw, tau, scale):
    """Valid share, gross flagged, gross among the valid, within 2 sigma, valid median: valid =
    raw <= tau (the threshold flag_threshold chose on validation), sigma = scale raw."""
    sigma = scale * raw
    valid, bad = raw <= tau, err > 45
    return [pct(valid.mean()), pct(np.mean(~valid[bad])) if bad.any() else "–",
            pct(np.mean(bad[valid])) if valid.any() else "–",
            pct(np.mean(err[valid] < 2 * np.degrees(sigma[valid]))) if valid.any() else "–",
            f"{np.median(err[valid]):.1f}°" if valid.any() else "–"]


def chosen(val, raw_v):
    """The validation rule on a score: the threshold (90 % of the gross errors flagged in every
    elevation band) and the scale (95 % of the valid within 2 sigma), unclamped."""
    tau = flag_threshold(val["err"], raw_v, val["tan2"])
    valid = raw_v <= tau
    return tau, float(np.percentile(np.radians(val["err"][valid]) / raw_v[valid], 95) / 2.0)


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--manifest", required=True)
    ap.add_argument("--model", required=True)
    ap.add_argument("--grey", action="store_true", help="feed every image as a grey camera")
    ap.add_argument("--pcs", type=int, default=4, help="principal coordinates per member")
    ap.add_argument("--seed", type=int, default=1)
    ap.add_argument("--out", help="also write the tables (markdown) here")
    a = ap.parse_args()
    cv2.setNumThreads(1)
    with open(os.path.splitext(a.model)[0] + ".json") as f:
        meta = json.load(f)
    cal = meta.get("gray_input", meta) if a.grey else meta
    if "feature_prior" not in meta:
        raise SystemExit(f"{a.model}: its JSON has no feature_prior")
    prior = feature_prior_from_json(meta["feature_prior"])
    net = cv2.dnn.readNetFromONNX(a.model)
    data = load(a.manifest)
    rng = np.random.default_rng(a.seed)
    per = {}
    for split in ("val", "test"):
        x, t, scen, sun = labelled(data, split, a.manifest, a.grey)
        dets, samps, trunk = run_model(net, meta, x, rng, layers=trunk_layers(net))
        trunk = np.stack(trunk)
        v, raw = combine(dets, samps)
        tan2 = elevation_tan2(sun)
        shipped = np.sqrt(raw ** 2 + cal.get("elevation_gain", 0.0) * tan2 +
                          cal.get("feature_gain", 0.0) *
                          feature_weakness(feature_distance(prior, trunk)))
        sig, names = signals(dets, samps, trunk, tan2, prior, a.pcs)
        per[split] = dict(err=np.abs(signed_deg(v, t)), shipped=shipped, x=sig, scen=scen,
                          tan2=tan2)
        print(f"{split}: {len(t)} images", file=sys.stderr)

    val, test = per["val"], per["test"]
    lines = ["| head | signals | lambda | val AUC (out of fold) | test AUC | val valid | "
             "val flagged | val gross among valid | val 2σ | val median (valid) | test valid | "
             "test flagged | test gross among valid | test 2σ | test median (valid) |",
             "| --- | ---: | ---: |" + " ---: |" * 12]
    tau, s = chosen(val, val["shipped"])
    lines.append(f"| shipped sigma | – | – | {auc(val['shipped'], val['err'] > 45):.3f} | "
                 f"{auc(test['shipped'], test['err'] > 45):.3f} | "
                 + " | ".join(scores(val["err"], val["shipped"], tau, s)
                              + scores(test["err"], test["shipped"], tau, s)) + " |")
    sets = {"scalars": [i for i, n in enumerate(names) if not n.startswith("z")],
            "scalars + z": list(range(len(names)))}
    for form, logistic, y in (("log-error", False, target(val["err"])),
                              ("gross", True, (val["err"] > 45).astype(float))):
        for label, cols in sets.items():
            for lam in LAMBDAS:
                xv, xt = val["x"][:, cols], test["x"][:, cols]
                # A sigma-like number: exp(pred / 2) (log-error), the probability (gross).
                to_raw = (lambda q: 1.0 / (1.0 + np.exp(-np.clip(q, -30, 30)))) if logistic \
                    else (lambda q: np.exp(q / 2))
                raw_v = to_raw(out_of_fold(xv, y, val["scen"], lam, logistic))
                raw_t = to_raw(Head(xv, y, lam, logistic)(xt))
                tau, s = chosen(val, raw_v)
                lines.append(f"| {form}, {label} | {len(cols)} | {lam:g} | "
                             f"{auc(raw_v, val['err'] > 45):.3f} | "
                             f"{auc(raw_t, test['err'] > 45):.3f} | "
                             + " | ".join(scores(val["err"], raw_v, tau, s)
                                          + scores(test["err"], raw_t, tau, s))
                             + " |")
    full = Head(val["x"], target(val["err"]), 1.0)
    lines += ["", "| signal | log-error head's weight (standardised, lambda 1) |", "| --- | ---: |"]
    lines += [f"| {n} | {w:+.3f} |" for n, w in zip(names, full.w[1:]) if not n.startswith("z")]
    table = "\n".join(lines)
    emit(table, a.out)


if __name__ == "__main__":
    main()
