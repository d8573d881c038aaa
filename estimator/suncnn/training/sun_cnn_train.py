#!/usr/bin/env python3
"""Trains Sun-CNN (sun azimuth from one image, with an uncertainty) on the manifest's training
rows, chooses the uncertainty's scale and the validity threshold on its validation rows, reports
its test rows, and exports the ONNX model with its JSON and a parity reference.

Sets (column `split` of the manifest, see sun_cnn_manifest.py):
  train  styled training renders (and real frames a user labels as training)
  val    validation: held-out places, times and styles; every choice below is made on it
  test   reported only: held-out test renders and real frames; no choice looks at it

The network and the exported graph are in sun_cnn_model.py. Augmentation (every batch):
random crop (75-100 % of each side) resized to 208x64, horizontal flip (az -> -az), white
balance, exposure, gamma, contrast, saturation, defocus blur, sensor noise, 20 % grey (colour
model), and 5 % images without sun cues (black, flat colour, noise) with target 0.
`--channels 1` trains the grey model (BT.601 luma of the same images) for grey cameras.

Members can train in separate processes, one core each, and be joined afterwards; at the same
thread count the joined ensemble is the one a single process trains, byte for byte:
  sun_cnn_train.py ... --members 1 --first-member K --save-members mK.pt   (K = 0, 1, 2)
  sun_cnn_train.py ... --load-members m0.pt m1.pt m2.pt                   (calibrate, export)
"""
import argparse
import csv
import datetime
import hashlib
import json
import math
import os
import sys
import time

import cv2
import numpy as np
import torch

from sun_cnn_model import (DROPOUT_P, FEAT, HIDDEN, IN_H, IN_W, K_ROWS, MEAN, STD, EnsembleExport,
                           SunCnn, calibrate_elevation, combine, elevation_tan2, mc_predict,
                           sigma_of, with_elevation)

LOAD_W, LOAD_H = 2 * IN_W, 2 * IN_H  # images are kept at twice the input size for the crops
LUMA = np.array([0.114, 0.587, 0.299], np.float32)  # BT.601, BGR order


def load(manifest):
    base = os.path.dirname(os.path.abspath(manifest))
    data = {}
    with open(manifest) as f:
        for line, r in enumerate(csv.DictReader(f), start=2):
            path = os.path.join(base, r["image"])
            img = cv2.imread(path, cv2.IMREAD_COLOR)  # grey files become (Y, Y, Y)
            if img is None:
                raise SystemExit(f"{manifest} line {line}: cannot read image {path}")
            try:
                s = np.array([float(r["sx"]), float(r["sy"]), float(r["sz"])])
            except ValueError as e:
                raise SystemExit(f"{manifest} line {line}: bad sun vector ({e})")
            d = data.setdefault(r["split"], ([], [], []))
            d[0].append(cv2.resize(img, (LOAD_W, LOAD_H), interpolation=cv2.INTER_AREA))
            d[1].append(s)
            d[2].append(r["scenario"])
    return {k: (np.stack(v[0]), np.stack(v[1]), v[2]) for k, v in data.items()}


def targets(sun):
    """(cos az, sin az) with az = atan2(x, z), and a weight: 0 when the sun is within ~11 deg
    of the camera's y axis (azimuth undefined)."""
    xz = np.hypot(sun[:, 0], sun[:, 2])
    t = np.stack([sun[:, 2], sun[:, 0]], 1) / np.maximum(xz, 1e-9)[:, None]
    return t.astype(np.float32), (xz > 0.2).astype(np.float32)


def labelled(data, split, manifest, grey=False):
    """One split of load()'s data, the rows whose azimuth is defined (targets' weight > 0):
    images (grey=True: as a grey camera gives them to a colour model), targets, scenarios and
    sun vectors. A manifest without the split is an error naming it."""
    if split not in data:
        raise SystemExit(f"{manifest}: no {split} rows")
    x, sun, scen = data[split]
    t, w = targets(sun)
    keep = w > 0
    x = grey_as_colour(x[keep]) if grey else x[keep]
    return x, t[keep], np.array(scen)[keep], sun[keep]


def to_input(bgr_float, channels):
    """N,H,W,3 float in [0, 255] -> N,C,H,W normalised tensor (grey: BT.601 luma)."""
    x = bgr_float if channels == 3 else (bgr_float @ LUMA)[..., None]
    x = torch.from_numpy(np.ascontiguousarray(x.transpose(0, 3, 1, 2), dtype=np.float32))
    return x.mul_(1.0 / (255.0 * STD)).sub_(MEAN / STD)


def grey_as_colour(u8):
    """N,H,W,3 uint8 BGR -> what a grey camera gives a colour model: the BT.601 luma, rounded to
    8 bits, in all three channels (the C++ estimator feeds a grey image as (Y, Y, Y))."""
    y = np.clip(np.rint(u8.astype(np.float32) @ LUMA), 0, 255).astype(np.uint8)
    return np.repeat(y[..., None], 3, axis=-1)


def plain(u8, channels):
    """Evaluation input: the whole image resized as the C++ side does (INTER_AREA)."""
    small = np.stack([cv2.resize(im, (IN_W, IN_H), interpolation=cv2.INTER_AREA) for im in u8])
    return to_input(small.astype(np.float32), channels)


def augment(u8, t, rng, channels, crop_min):
    n = len(u8)
    t = t.copy()
    out = np.empty((n, IN_H, IN_W, 3), np.float32)
    for i in range(n):
        cw = int(LOAD_W * rng.uniform(crop_min, 1.0))
        ch = int(LOAD_H * rng.uniform(crop_min, 1.0))
        x0, y0 = rng.integers(0, LOAD_W - cw + 1), rng.integers(0, LOAD_H - ch + 1)
        out[i] = cv2.resize(u8[i, y0:y0 + ch, x0:x0 + cw], (IN_W, IN_H),
                            interpolation=cv2.INTER_AREA)
        if rng.random() < 0.3:
            out[i] = cv2.GaussianBlur(out[i], (0, 0), rng.uniform(0.3, 1.2))
    flip = rng.random(n) < 0.5
    out[flip] = out[flip, :, ::-1]
    t[flip, 1] *= -1

    def draw(lo, hi, shape):  # the random factors in float32, so that the batch stays float32
        return rng.uniform(lo, hi, shape).astype(np.float32)

    x = out * np.float32(1.0 / 255.0)
    x *= draw(0.75, 1.3, (n, 1, 1, 3)) * draw(0.5, 1.6, (n, 1, 1, 1))
    np.clip(x, 0, 1, out=x)
    x **= draw(0.6, 1.7, (n, 1, 1, 1))
    m = x.mean((1, 2, 3), keepdims=True)
    x -= m
    x *= draw(0.6, 1.4, (n, 1, 1, 1))
    x += m
    grey = (x @ LUMA)[..., None]
    x -= grey
    x *= draw(0.0, 1.4, (n, 1, 1, 1))
    x += grey
    x += rng.standard_normal(x.shape, dtype=np.float32) * draw(0, 0.03, (n, 1, 1, 1))
    if channels == 3:  # 20 % grey, so that grey cameras can be fed to the colour model
        g = rng.random(n) < 0.2
        x[g] = (x[g] @ LUMA)[..., None]
    np.clip(x, 0, 1, out=x)
    x *= np.float32(255.0)
    deg = rng.random(n) < 0.05
    for i in np.nonzero(deg)[0]:
        kind = rng.integers(3)
        x[i] = (rng.uniform(0, 12) if kind == 0 else rng.uniform(0, 255, 3)[None, None, :]
                if kind == 1 else rng.uniform(0, 255, x[i].shape))
        t[i] = 0
    return to_input(x, channels), torch.from_numpy(t), torch.from_numpy(
        deg.astype(np.float32))


def train_member(xtr, ttr, wtr, a, seed, log):
    epochs, channels = a.epochs, a.channels
    torch.manual_seed(seed)
    rng = np.random.default_rng(seed)
    model = SunCnn(channels, a.width, a.depth)
    opt = torch.optim.AdamW(model.parameters(), lr=2e-3, weight_decay=1e-4)
    bs = 64
    steps = epochs * math.ceil(len(xtr) / bs)
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, max_lr=3e-3, total_steps=steps)
    t0 = time.time()
    for ep in range(epochs):
        model.train()
        perm = rng.permutation(len(xtr))
        tot = 0.0
        for i in range(0, len(perm), bs):
            idx = np.sort(perm[i:i + bs])
            x, t, deg = augment(xtr[idx], ttr[idx], rng, channels, a.crop_min)
            w = torch.maximum(torch.from_numpy(wtr[idx]), deg)
            loss = ((model(x) - t) ** 2).sum(1).mul(w).sum() / w.sum().clamp(min=1)
            opt.zero_grad()
            loss.backward()
            opt.step()
            sched.step()
            tot += loss.item() * len(idx)
        log(f"seed {seed} epoch {ep + 1}/{epochs} loss {tot / len(perm):.4f} "
            f"({time.time() - t0:.0f} s)")
    return model.eval()


def signed_deg(v, t):
    a = np.degrees(np.arctan2(v[:, 1], v[:, 0]) - np.arctan2(t[:, 1], t[:, 0]))
    return (a + 180) % 360 - 180


def metrics(err_signed, sigma, valid):
    """The statistics of one set; a statistic without frames to count is left out (the C++
    side reads the JSON with OpenCV's parser, which has no null)."""
    err = np.abs(err_signed)
    gross = err > 45
    out = {
        "images": int(len(err)),
        "median_deg": float(np.median(err)),
        "p90_deg": float(np.percentile(err, 90)),
        "signed_median_deg": float(np.median(err_signed)),
        "gross_share": float(gross.mean()),
        "valid_share": float(valid.mean()),
        "gross_flagged_share": float((~valid[gross]).mean()) if gross.any() else None,
        "valid_median_deg": float(np.median(err[valid])) if valid.any() else None,
        "valid_gross_share": float(gross[valid].mean()) if valid.any() else None,
        "within_2sigma_share": float((np.radians(err[valid]) < 2 * sigma[valid]).mean())
        if valid.any() else None,
    }
    return {k: v for k, v in out.items() if v is not None}


def evaluate(members, split, channels, seed):
    x, sun, scen = split
    t, w = targets(sun)
    keep = w > 0
    dets, samps = mc_predict(members, plain(x, channels), 16, torch.Generator().manual_seed(seed))
    v, raw = combine(dets, samps)
    return signed_deg(v, t)[keep], raw[keep], np.array(scen)[keep], elevation_tan2(sun[keep])


def report(err, raw, scen, scale, threshold):
    sigma = sigma_of(raw, scale)
    valid = sigma <= threshold
    out = {"all": metrics(err, sigma, valid)}
    for s in sorted(set(scen)):
        m = scen == s
        out[s] = metrics(err[m], sigma[m], valid[m])
    return out


def write_reference(path, ex, channels, onnx_path, model_hash):
    """Closed-form input and two mask patterns; PyTorch's outputs for member 0 (rows 0, 1) and
    the last member (row (M-1)K). tests/suncnn rebuilds the same input in C++."""
    c, y, x = np.meshgrid(np.arange(channels), np.arange(IN_H), np.arange(IN_W), indexing="ij")
    ref_in = (((c * 7 + y * 13 + x * 3) % 29) / 29.0 - 0.5).astype(np.float32)[None]
    keep = 1.0 / (1.0 - DROPOUT_P)
    m1 = np.ones((K_ROWS, FEAT), np.float32)
    m2 = np.ones((K_ROWS, HIDDEN), np.float32)
    m1[1] = np.where(np.arange(FEAT) % 3 == 0, 0.0, keep)
    m2[1] = np.where(np.arange(HIDDEN) % 4 == 1, 0.0, keep)
    with torch.no_grad():
        out = ex(torch.from_numpy(ref_in), torch.from_numpy(m1), torch.from_numpy(m2)).numpy()
    last = (len(ex.members) - 1) * K_ROWS
    with open(path, "w") as f:
        f.write(f"# Sun-CNN parity reference written by sun_cnn_train.py (PyTorch {torch.__version__}).\n")
        f.write("# input[c,y,x] = ((7c + 13y + 3x) mod 29) / 29 - 0.5; row 0: masks all ones;\n")
        f.write("# row 1: mask1[j] = 0 if j mod 3 == 0, mask2[j] = 0 if j mod 4 == 1, else 1/(1-p);\n")
        f.write("# row (M-1)K: the last member, masks all ones.\n")
        f.write(f"model_sha256 {model_hash}\nmodel_bytes {os.path.getsize(onnx_path)}\n")
        f.write(f"channels {channels}\nmembers {len(ex.members)}\n")
        for r in (0, 1, last):
            f.write(f"row {r} {out[r, 0]:.8e} {out[r, 1]:.8e}\n")


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--manifest", required=True)
    ap.add_argument("--out-dir", required=True)
    ap.add_argument("--reference", required=True)
    ap.add_argument("--name", default="sun_cnn", help="output files <name>.onnx, <name>.json")
    ap.add_argument("--channels", type=int, choices=(1, 3), default=3)
    ap.add_argument("--members", type=int, default=3)
    ap.add_argument("--epochs", type=int, default=40)
    ap.add_argument("--width", type=int, default=1, help="channel multiplier of the trunk")
    ap.add_argument("--depth", type=int, default=1,
                    help="3x3 convs in each of the trunk's last three stages")
    ap.add_argument("--crop-min", type=float, default=0.75,
                    help="smallest random crop, share of each side")
    ap.add_argument("--loss-weight", choices=("scored", "horizontal"), default="scored",
                    help="training frames' loss weight: 1 where the azimuth is scored, or that "
                         "times the horizontal share of the sun direction")
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seed", type=int, default=20261125)
    ap.add_argument("--first-member", type=int, default=0,
                    help="member m trains from seed + first_member + m (members trained in "
                         "separate processes, then joined with --load-members)")
    ap.add_argument("--save-members", metavar="PT",
                    help="also write the trained members' weights (torch.save) to PT")
    ap.add_argument("--load-members", metavar="PT", nargs="+",
                    help="train nothing: take the members saved by --save-members runs, in "
                         "order, and calibrate, report and export them as one ensemble")
    a = ap.parse_args()
    torch.set_num_threads(a.threads)
    torch.use_deterministic_algorithms(True)
    log = lambda s: print(s, file=sys.stderr, flush=True)  # noqa: E731
    with open(a.manifest + ".sha256") as f:
        data_hash = f.read().strip()
    t0 = time.time()
    data = load(a.manifest)
    if "train" not in data:
        raise SystemExit(f"{a.manifest}: no training rows")
    xtr, sun_tr, _ = data["train"]
    ttr, wtr = targets(sun_tr)
    if a.loss_weight == "horizontal":
        # How well an image defines the azimuth: shadows shorten and the sky's azimuthal
        # gradient fades as the sun climbs, so a frame counts by the horizontal share of the sun
        # direction (cos of its angle above the camera's x-z plane).
        wtr = wtr * np.hypot(sun_tr[:, 0], sun_tr[:, 2]).astype(np.float32)
    log(f"loaded {sum(len(v[0]) for v in data.values())} images in {time.time() - t0:.0f} s")
    t_train = time.time()
    if a.load_members:
        saved = [torch.load(path) for path in a.load_members]
        if any(s["channels"] != a.channels or s["epochs"] != a.epochs for s in saved):
            raise SystemExit("--load-members: channels or epochs differ from this run's")
        members = []
        for s in saved:
            for state in s["members"]:
                members.append(SunCnn(a.channels, a.width, a.depth))
                members[-1].load_state_dict(state)
                members[-1].eval()
        a.members = len(members)
        train_s = sum(s["train_seconds"] for s in saved)
    else:
        members = [train_member(xtr, ttr, wtr, a, a.seed + a.first_member + m, log)
                   for m in range(a.members)]
        train_s = time.time() - t_train
    if a.save_members:
        torch.save({"members": [m.state_dict() for m in members], "channels": a.channels,
                    "epochs": a.epochs, "train_seconds": train_s}, a.save_members)

    # Choices on the validation rows only: the elevation gain, the validity threshold and the
    # sigma scale (sun_cnn_model.calibrate_elevation).
    gain, scale, threshold, results = 0.0, 1.0, 0.5, {}
    if "val" in data:
        err, raw, scen, tan2 = evaluate(members, data["val"], a.channels, a.seed)
        gain, scale, threshold = calibrate_elevation(err, raw, tan2)
        results["val"] = report(err, with_elevation(raw, tan2, gain), scen, scale, threshold)
    for split in ("train", "test"):
        if split in data:
            err, raw, scen, tan2 = evaluate(members, data[split], a.channels, a.seed)
            results[split] = report(err, with_elevation(raw, tan2, gain), scen, scale, threshold)
    # A colour model also serves grey cameras, fed (Y, Y, Y): their answers get their own
    # threshold and scale, chosen the same way on the validation rows' luma.
    gray_input = {}
    if a.channels == 3 and "val" in data:
        g_evals = {k: evaluate(members, (grey_as_colour(data[k][0]),) + data[k][1:], 3, a.seed)
                   for k in ("val", "test") if k in data}
        g_err, g_raw, _, g_tan2 = g_evals["val"]
        g_gain, g_scale, g_threshold = calibrate_elevation(g_err, g_raw, g_tan2)
        gray_input = {"sigma_scale": g_scale, "max_valid_sigma_rad": g_threshold,
                      "elevation_gain": g_gain,
                      "results": {k: report(e, with_elevation(r, t2, g_gain), s, g_scale,
                                            g_threshold) for k, (e, r, s, t2) in g_evals.items()}}
    for split, r in list(results.items()) + [
            ("grey " + k, v) for k, v in gray_input.get("results", {}).items()]:
        for scenario, m in r.items():
            log(f"{split} {scenario}: median {m['median_deg']:.1f} deg, p90 {m['p90_deg']:.1f}, "
                f"bias {m['signed_median_deg']:+.1f}, gross {100 * m['gross_share']:.1f} %, "
                f"valid {100 * m['valid_share']:.0f} %, gross flagged "
                f"{100 * m.get('gross_flagged_share', float('nan')):.0f} %, within 2 sigma "
                f"{100 * m.get('within_2sigma_share', float('nan')):.0f} %, n {m['images']}")

    onnx_path = os.path.join(a.out_dir, a.name + ".onnx")
    ex = EnsembleExport(members).eval()
    dummy = (torch.zeros(1, a.channels, IN_H, IN_W), torch.ones(K_ROWS, FEAT),
             torch.ones(K_ROWS, HIDDEN))
    torch.onnx.export(ex, dummy, onnx_path, opset_version=11,
                      input_names=["image", "mask1", "mask2"], output_names=["azimuth_cs"],
                      do_constant_folding=True)
    with open(onnx_path, "rb") as f:
        model_hash = hashlib.sha256(f.read()).hexdigest()
    os.makedirs(os.path.dirname(os.path.abspath(a.reference)), exist_ok=True)
    write_reference(a.reference, ex, a.channels, onnx_path, model_hash)
    meta = {
        "model": a.name + ".onnx",
        "model_sha256": model_hash,
        "input": {"width": IN_W, "height": IN_H, "channels": a.channels,
                  "channel_order": "BGR" if a.channels == 3 else "grey (BT.601 luma)",
                  "resize": "cv::INTER_AREA", "normalisation": f"(pixel / 255 - {MEAN}) / {STD}"},
        "mc": {"members": a.members, "rows": K_ROWS, "mask1": FEAT, "mask2": HIDDEN,
               "dropout_p": DROPOUT_P},
        "output": "[members * rows, 2]: (cos az, sin az), az = atan2(sun_x, sun_z) in camera 0",
        "sigma_scale": scale,
        "max_valid_sigma_rad": threshold,
        "elevation_gain": gain,
        "training_data_sha256": data_hash,
        "training_images": int(len(xtr)),
        "training_command": "bash scripts/train_sun_cnn.sh",
        "epochs": a.epochs,
        "width": a.width,
        "depth": a.depth,
        "crop_min": a.crop_min,
        "seed": a.seed,
        "train_seconds": round(train_s, 1),
        "results": results,
        **({"gray_input": gray_input} if gray_input else {}),
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "torch": torch.__version__,
    }
    with open(os.path.join(a.out_dir, a.name + ".json"), "w") as f:
        json.dump(meta, f, indent=2)
        f.write("\n")
    log(f"wrote {onnx_path} ({model_hash[:12]}), training {train_s:.0f} s")


if __name__ == "__main__":
    main()
