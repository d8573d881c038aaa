#!/usr/bin/env python3
"""Trains Sun-CNN: one colour image -> sun azimuth in the camera x-z plane, with MC dropout.

Model: a 5x5 stride-2 conv and three 3x3 convs (each BN, ReLU, 2x2 max-pool) on a 64x208 BGR
image (about 13.5 M multiply-adds), flattened
(64 x 2 x 6 = 768 features), then dropout -> FC 128 -> ReLU -> dropout -> FC 2. The output
v = (c, s) is regressed onto t = (cos az, sin az), az = atan2(sun_x, sun_z), with the squared
chord ||v - t||^2 (targets on the unit circle). The minimiser of the expected chord loss is
E[t | image], whose length is the mean resultant length of the azimuth posterior: images without
sun cues (black, flat, noise; 5 % synthesised per batch with t = 0) are taught to answer v = 0,
which the C++ side turns into a large sigma.

Export (ONNX opset 11, read by OpenCV 4.6 DNN): inputs image [1,3,64,208], mask1 [K,768],
mask2 [K,128]; output [K,2]. The trunk runs once, its features are repeated K times (Concat)
and multiplied by the masks (inverted dropout: entries 0 or 1/(1-p); all ones = dropout off).
Row k of the output is then one dropout sample, so MC dropout costs one trunk pass plus K cheap
head passes, and the caller owns the random numbers (reproducible, testable).
"""
import argparse
import csv
import datetime
import hashlib
import json
import math
import os
import random
import sys
import time

import cv2
import numpy as np
import torch
import torch.nn as nn

IN_H, IN_W = 64, 208
MEAN, STD = 0.5, 0.25  # x = (pixel / 255 - MEAN) / STD, every channel, BGR order
DROPOUT_P = 0.3
K_ROWS = 32  # rows of the exported head (1 deterministic + up to 31 MC samples)
FEAT, HIDDEN = 64 * 2 * 6, 128


class SunCnn(nn.Module):
    def __init__(self):
        super().__init__()
        # 64x208 -> (5x5 stride-2 conv, pool) 16x52 -> 8x26 -> 4x13 -> 2x6 (x64 channels).
        layers = [nn.Conv2d(3, 16, 5, stride=2, padding=2, bias=False), nn.BatchNorm2d(16),
                  nn.ReLU(), nn.MaxPool2d(2)]
        for a, b in ((16, 32), (32, 64), (64, 64)):
            layers += [nn.Conv2d(a, b, 3, padding=1, bias=False), nn.BatchNorm2d(b), nn.ReLU(),
                       nn.MaxPool2d(2)]
        self.trunk = nn.Sequential(*layers)
        self.fc1 = nn.Linear(FEAT, HIDDEN)
        self.fc2 = nn.Linear(HIDDEN, 2)
        self.drop = nn.Dropout(DROPOUT_P)

    def features(self, x):
        return torch.flatten(self.trunk(x), 1)

    def forward(self, x):
        h = torch.relu(self.fc1(self.drop(self.features(x))))
        return self.fc2(self.drop(h))


class SunCnnExport(nn.Module):
    """The exported graph: trunk once, K masked head passes."""

    def __init__(self, m):
        super().__init__()
        self.m = m

    def forward(self, image, mask1, mask2):
        f = self.m.features(image)
        f = torch.cat([f] * K_ROWS, 0) * mask1
        h = torch.relu(self.m.fc1(f)) * mask2
        return self.m.fc2(h)


def preprocess(bgr):
    small = cv2.resize(bgr, (IN_W, IN_H), interpolation=cv2.INTER_AREA)
    return small


def to_tensor(u8):  # N,H,W,3 uint8 -> N,3,H,W float
    x = torch.from_numpy(u8).permute(0, 3, 1, 2).float()
    return (x / 255.0 - MEAN) / STD


def load(manifest, renders):
    data = {"train": ([], [], []), "val": ([], [], [])}
    with open(manifest) as f:
        for line, r in enumerate(csv.DictReader(f), start=2):
            img = cv2.imread(os.path.join(renders, r["image"]), cv2.IMREAD_COLOR)
            if img is None:
                raise SystemExit(f"{manifest} line {line}: cannot read image {r['image']}")
            s = np.array([float(r["sx"]), float(r["sy"]), float(r["sz"])])
            d = data[r["split"]]
            d[0].append(preprocess(img))
            d[1].append(s)
            d[2].append(r["scenario"])
    return {k: (np.stack(v[0]), np.stack(v[1]), v[2]) for k, v in data.items() if v[0]}


def targets(sun):
    """(cos az, sin az) with az = atan2(x, z), and a weight: 0 when the sun is within ~11 deg
    of the camera's y axis (azimuth undefined)."""
    xz = np.hypot(sun[:, 0], sun[:, 2])
    t = np.stack([sun[:, 2], sun[:, 0]], 1) / np.maximum(xz, 1e-9)[:, None]
    return t.astype(np.float32), (xz > 0.2).astype(np.float32)


def augment(u8, t, rng):
    """Horizontal flip (az -> -az), exposure/colour gain, grey, small horizontal shift; 5 % degenerate
    images (black, flat colour, noise) with target 0."""
    x = u8.astype(np.float32)
    t = t.copy()
    n = len(x)
    flip = rng.random(n) < 0.5
    x[flip] = x[flip, :, ::-1]
    t[flip, 1] *= -1
    gain = rng.uniform(0.6, 1.4, (n, 1, 1, 1)) * rng.uniform(0.9, 1.1, (n, 1, 1, 3))
    x = np.clip(x * gain, 0, 255).astype(np.float32)
    # 20 % grey (BT.601 luma in all three channels), so that grey cameras (KITTI odometry's
    # image_0) can be fed as BGR = (Y, Y, Y).
    grey = rng.random(n) < 0.2
    x[grey] = (x[grey] @ np.array([0.114, 0.587, 0.299], np.float32))[..., None]
    for i in range(n):
        sh = int(rng.integers(-3, 4))
        if sh:
            x[i] = np.roll(x[i], sh, axis=1)
    deg = rng.random(n) < 0.05
    for i in np.nonzero(deg)[0]:
        kind = rng.integers(3)
        if kind == 0:
            x[i] = rng.uniform(0, 12)
        elif kind == 1:
            x[i] = rng.uniform(0, 255, 3)[None, None, :]
        else:
            x[i] = rng.uniform(0, 255, x[i].shape)
        t[i] = 0
    x = (torch.from_numpy(np.ascontiguousarray(x)).permute(0, 3, 1, 2) / 255.0 - MEAN) / STD
    return x, torch.from_numpy(t), torch.from_numpy(deg.astype(np.float32))


def angle_err_deg(v, t):
    a = np.degrees(np.arctan2(v[:, 1], v[:, 0]) - np.arctan2(t[:, 1], t[:, 0]))
    return np.abs((a + 180) % 360 - 180)


def mc_predict(model, x, samples, gen):
    """Deterministic output and `samples` dropout outputs per image (same masks as the export)."""
    model.eval()
    with torch.no_grad():
        f = model.features(x)
        det = model.fc2(torch.relu(model.fc1(f)))
        outs = []
        for _ in range(samples):
            m1 = (torch.rand(f.shape, generator=gen) >= DROPOUT_P).float() / (1 - DROPOUT_P)
            h = torch.relu(model.fc1(f * m1))
            m2 = (torch.rand(h.shape, generator=gen) >= DROPOUT_P).float() / (1 - DROPOUT_P)
            outs.append(model.fc2(h * m2))
    return det.numpy(), torch.stack(outs, 1).numpy()


def spread_sigma(det, samples):
    """Circular sigma (rad) of the MC samples plus the aleatoric part from the shrinkage of the
    deterministic output: sqrt(-2 ln R) for each, added in quadrature (as the C++ side does)."""
    u = samples / np.maximum(np.linalg.norm(samples, axis=2, keepdims=True), 1e-9)
    r_mc = np.clip(np.linalg.norm(u.mean(1), axis=1), 1e-6, 1.0)
    r_al = np.clip(np.linalg.norm(det, axis=1), 1e-6, 1.0)
    return np.sqrt(-2 * np.log(r_mc) - 2 * np.log(r_al))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--manifest", required=True)
    ap.add_argument("--out-dir", required=True)
    ap.add_argument("--reference", required=True)
    ap.add_argument("--epochs", type=int, default=48)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--seed", type=int, default=20261122)
    a = ap.parse_args()
    torch.manual_seed(a.seed)
    random.seed(a.seed)
    np.random.seed(a.seed)
    torch.set_num_threads(a.threads)
    torch.use_deterministic_algorithms(True)
    renders = os.path.dirname(os.path.abspath(a.manifest))
    with open(a.manifest + ".sha256") as f:
        data_hash = f.read().strip()
    t0 = time.time()
    data = load(a.manifest, renders)
    xtr, str_, _ = data["train"]
    ttr, wtr = targets(str_)
    print(f"loaded {len(xtr)} training images in {time.time() - t0:.0f} s", file=sys.stderr)

    model = SunCnn()
    opt = torch.optim.AdamW(model.parameters(), lr=2e-3, weight_decay=1e-4)
    bs = 64
    steps = a.epochs * math.ceil(len(xtr) // 2 / bs)
    sched = torch.optim.lr_scheduler.OneCycleLR(opt, max_lr=3e-3, total_steps=steps)
    rng = np.random.default_rng(a.seed)
    t_train = time.time()
    # Rows come in stereo pairs (image_02, image_03 of one frame, same sun in the camera frame):
    # an epoch visits every frame once, through one of its two cameras at random.
    if len(xtr) % 2 or not np.array_equal(str_[0::2], str_[1::2]):
        raise SystemExit("manifest: training rows are not (image_02, image_03) pairs")
    n_frames = len(xtr) // 2
    for ep in range(a.epochs):
        model.train()
        perm = 2 * rng.permutation(n_frames) + rng.integers(0, 2, n_frames)
        tot, cnt = 0.0, 0
        for i in range(0, len(perm), bs):
            idx = perm[i:i + bs]
            x, t, deg = augment(xtr[idx], ttr[idx], rng)
            w = torch.maximum(torch.from_numpy(wtr[idx]), deg)
            v = model(x)
            loss = ((v - t) ** 2).sum(1).mul(w).sum() / w.sum().clamp(min=1)
            opt.zero_grad()
            loss.backward()
            opt.step()
            sched.step()
            tot += loss.item() * len(idx)
            cnt += len(idx)
        print(f"epoch {ep + 1}/{a.epochs} loss {tot / cnt:.4f} ({time.time() - t_train:.0f} s)",
              file=sys.stderr)
    train_s = time.time() - t_train

    # Held-out evaluation (scenarios never trained on; not used for any choice in training).
    gen = torch.Generator().manual_seed(a.seed)
    report = {}
    if "val" in data:
        xv, sv, scen = data["val"]
        tv, wv = targets(sv)
        keep = wv > 0
        det, samp = mc_predict(model, to_tensor(xv), 16, gen)
        err = angle_err_deg(det, tv)[keep]
        sig = spread_sigma(det, samp)[keep]
        # One scale so that the median of |err| / sigma over the images is the Gaussian 0.674.
        # (The ratio of the two medians, used before, left the per-image ratio at about 1.0.)
        scale = float(np.median(np.radians(err) / sig) / 0.6745)
        report = {
            "images": int(keep.sum()),
            "scenarios": sorted(set(scen)),
            "median_deg": float(np.median(err)),
            "p90_deg": float(np.percentile(err, 90)),
            "gross_gt45_share": float(np.mean(err > 45)),
            "sigma_scale": scale,
        }
        for s in sorted(set(scen)):
            m = np.array([c == s for c in scen])[keep]
            report["median_deg_" + s] = float(np.median(err[m]))
        print("held-out:", json.dumps(report), file=sys.stderr)

    # Export.
    model.eval()
    onnx_path = os.path.join(a.out_dir, "sun_cnn.onnx")
    ex = SunCnnExport(model).eval()
    dummy = (torch.zeros(1, 3, IN_H, IN_W), torch.ones(K_ROWS, FEAT), torch.ones(K_ROWS, HIDDEN))
    torch.onnx.export(ex, dummy, onnx_path, opset_version=11, input_names=["image", "mask1", "mask2"],
                      output_names=["azimuth_cs"], do_constant_folding=True)
    with open(onnx_path, "rb") as f:
        model_hash = hashlib.sha256(f.read()).hexdigest()

    # Parity reference: a closed-form input and two mask patterns (all ones = dropout off; a
    # fixed pattern), outputs from PyTorch. tests/suncnn rebuilds the same input in C++.
    c, y, x = np.meshgrid(np.arange(3), np.arange(IN_H), np.arange(IN_W), indexing="ij")
    ref_in = (((c * 7 + y * 13 + x * 3) % 29) / 29.0 - 0.5).astype(np.float32)[None]
    keep_val = 1.0 / (1.0 - DROPOUT_P)
    m1 = np.ones((K_ROWS, FEAT), np.float32)
    m2 = np.ones((K_ROWS, HIDDEN), np.float32)
    m1[1] = np.where(np.arange(FEAT) % 3 == 0, 0.0, keep_val)
    m2[1] = np.where(np.arange(HIDDEN) % 4 == 1, 0.0, keep_val)
    with torch.no_grad():
        ref_out = ex(torch.from_numpy(ref_in), torch.from_numpy(m1), torch.from_numpy(m2)).numpy()
    os.makedirs(os.path.dirname(a.reference), exist_ok=True)
    with open(a.reference, "w") as f:
        f.write("# Sun-CNN parity reference written by sun_cnn_train.py (PyTorch %s).\n"
                % torch.__version__)
        f.write("# input[c,y,x] = ((7c + 13y + 3x) mod 29) / 29 - 0.5; row 0: masks all ones;\n")
        f.write("# row 1: mask1[j] = 0 if j mod 3 == 0, mask2[j] = 0 if j mod 4 == 1, else 1/(1-p).\n")
        f.write(f"model_sha256 {model_hash}\n")
        f.write(f"model_bytes {os.path.getsize(onnx_path)}\n")
        for r in (0, 1):
            f.write(f"row{r} {ref_out[r, 0]:.8e} {ref_out[r, 1]:.8e}\n")

    meta = {
        "model": "sun_cnn.onnx",
        "model_sha256": model_hash,
        "input": {"width": IN_W, "height": IN_H, "channels": "BGR", "resize": "cv::INTER_AREA",
                  "normalisation": f"(pixel / 255 - {MEAN}) / {STD}"},
        "mc": {"rows": K_ROWS, "mask1": FEAT, "mask2": HIDDEN, "dropout_p": DROPOUT_P},
        "output": "(cos az, sin az), az = atan2(sun_x, sun_z) in camera 0",
        "training_data_sha256": data_hash,
        "training_images": int(len(xtr)),
        "training_frames": int(n_frames),
        "training_command": "bash scripts/train_sun_cnn.sh",
        "epochs": a.epochs,
        "seed": a.seed,
        "train_seconds": round(train_s, 1),
        "heldout_validation": report,
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC"),
        "torch": torch.__version__,
    }
    with open(os.path.join(a.out_dir, "sun_cnn.json"), "w") as f:
        json.dump(meta, f, indent=2)
        f.write("\n")
    print(f"wrote {onnx_path} ({model_hash[:12]}), training {train_s:.0f} s", file=sys.stderr)


if __name__ == "__main__":
    main()
