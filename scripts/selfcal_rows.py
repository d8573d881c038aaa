#!/usr/bin/env python3
"""How well the right rows of a rendered drive measure its rig error (issue 15, docs/selfcal.md).

Reads a track folder written by `sunvo_replay --drive D --no-error-models --self-calib
--write-tracks T` (the rows are measured only with the self-calibration on) and the drive's
injected rig error `D/gt/rig_error.csv`, and prints, for the observations whose right row was
measured:
  - the residual r = (vL - vR) - (vL - vR)_true of the self-calibration's model
    (docs: estimator/selfcal/include/sunvo/selfcal/stereo_self_calibration.hpp), its mean and std;
  - the correlation of one landmark's r between consecutive frames (how much a track's row error
    persists, i.e. whether counting every frame's rows as independent overstates the
    information);
  - a per-frame least-squares fit of (pitch, roll, scale) from that frame's rows alone: its slope
    against the truth, its spread about it against the filter's per-frame sigma at sigma_px, and
    the lag-1 autocorrelation of its error;
  - r by image column.
The renderer's right_roll_deg turns the image the other way from the filter's theta (measured:
with theta = +roll the residual's mean is -0.48 px on the CI rig drive, with -roll 0.01 px).
Needs numpy (bash scripts/setup.sh --train). Usage: selfcal_rows.py TRACKS RIG_ERROR_CSV
[--sigma-px 0.5]
"""
import argparse
import math

import numpy as np


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("tracks", help="track folder (calib.txt, tracks.csv with vR_measured)")
    ap.add_argument("rig_error", help="the drive's gt/rig_error.csv")
    ap.add_argument("--sigma-px", type=float, default=0.5, help="the filter's row sigma, px")
    ap.add_argument("--gate-px", type=float, default=1.5, help="residuals beyond are left out")
    a = ap.parse_args()
    calib = [float(x) for x in open(a.tracks + "/calib.txt").read().split()]
    fu, fv, cu, cv = calib[:4]
    d = np.genfromtxt(a.tracks + "/tracks.csv", delimiter=",", skip_header=1)
    if d.shape[1] < 7:
        raise SystemExit(f"{a.tracks}/tracks.csv: no vR_measured column (write it with --self-calib)")
    d = d[d[:, 6] == 1]
    if len(d) == 0:
        raise SystemExit(f"{a.tracks}/tracks.csv: no measured right rows (write it with --self-calib)")
    rig = np.genfromtxt(a.rig_error, delimiter=",", skip_header=1)
    frame = d[:, 0].astype(int)
    if frame.max() >= len(rig):
        raise SystemExit(f"{a.rig_error}: {len(rig)} rows, tracks reach frame {frame.max()}")
    theta = np.radians(-rig[frame, 1])  # the filter's roll (see the docstring)
    delta = np.radians(rig[frame, 2])
    y = d[:, 3] - d[:, 5]
    y_true = -fv * delta - theta * (d[:, 4] - cu)
    r = y - y_true
    keep = np.abs(r) < a.gate_px
    d, frame, y, y_true, r = d[keep], frame[keep], y[keep], y_true[keep], r[keep]
    theta, delta = theta[keep], delta[keep]
    print(f"{len(r)} measured rows within {a.gate_px} px: residual mean {r.mean():+.4f} px, "
          f"std {r.std():.4f} px (the filter assumes {a.sigma_px} px)")
    # Pixel locking: a subpixel estimate drawn towards whole pixels reads offsets just past a
    # whole pixel short. Uniform fractional parts would put 2 % within 0.01 px of one.
    frac = np.abs(y - np.round(y))
    print(f"measured offsets within 0.01 / 0.02 px of a whole pixel: {100 * (frac < 0.01).mean():.1f}"
          f" / {100 * (frac < 0.02).mean():.1f} % (2 / 4 % if not drawn to them)")

    by_key = {(f, int(lm)): v for f, lm, v in zip(frame, d[:, 1], r)}
    pairs = np.array([(v, by_key[(f + 1, lm)]) for (f, lm), v in by_key.items()
                      if (f + 1, lm) in by_key])
    if len(pairs) > 2:
        print(f"one landmark's residual in consecutive frames: {len(pairs)} pairs, correlation "
              f"{np.corrcoef(pairs[:, 0], pairs[:, 1])[0, 1]:.3f}")

    est, truth, sig = [], [], []
    for f in np.unique(frame):
        m = frame == f
        if m.sum() < 10:
            continue
        H = np.stack([-fv * np.ones(m.sum()), -(d[m, 4] - cu), -(d[m, 5] - cv)], 1)
        x, *_ = np.linalg.lstsq(H, y[m], rcond=None)
        cov = np.linalg.inv(H.T @ H) * a.sigma_px ** 2
        est.append(x[:2])
        truth.append((delta[m][0], theta[m][0]))
        sig.append(math.sqrt(cov[1, 1]))
    est, truth = np.degrees(np.array(est)), np.degrees(np.array(truth))
    for i, name in ((0, "pitch"), (1, "roll")):
        e, t = est[:, i], truth[:, i]
        err = e - t
        slope = (f", slope against the truth {np.polyfit(t, e, 1)[0]:.3f}"
                 if t.max() - t.min() > 1e-6 else "")  # a constant truth has no slope
        print(f"per-frame {name} from the rows alone ({len(e)} frames): truth {t[0]:+.4f} -> "
              f"{t[-1]:+.4f} deg, error mean {err.mean():+.5f} deg (first / last 25 frames "
              f"{err[:25].mean():+.5f} / {err[-25:].mean():+.5f}), std {err.std():.5f} deg, "
              f"lag-1 autocorrelation {np.corrcoef(err[:-1], err[1:])[0, 1]:.3f}{slope}")
    print(f"the filter's per-frame roll sigma at {a.sigma_px} px: median "
          f"{math.degrees(np.median(sig)):.5f} deg")
    # Image width: calib.txt's sixth field where it states the size, else past the widest column.
    w = calib[5] if len(calib) >= 7 else d[:, 4].max() + 1
    for lo, hi in ((0, 0.15), (0.15, 0.35), (0.35, 0.5), (0.5, 0.65), (0.65, 0.85), (0.85, 1.0)):
        m = (d[:, 4] >= lo * w) & (d[:, 4] < hi * w)
        if m.sum() > 30:
            print(f"  uR {lo * w:6.0f}-{hi * w:6.0f} px: {m.sum():6d} rows, true offset "
                  f"{y_true[m].mean():+.3f} px, measured {y[m].mean():+.3f} px, residual "
                  f"{r[m].mean():+.3f} px")


if __name__ == "__main__":
    main()
