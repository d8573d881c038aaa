#!/usr/bin/env python3
"""The learned confidence head's study tool (estimator/suncnn/training/sun_cnn_head.py): the ridge
and logistic heads, the out-of-fold scores by drive, and the validity rule it shares with the
shipped calibration (sun_cnn_model.flag_threshold). Needs numpy (sun_cnn_model imports torch:
Debian's python3-torch).

    sun_cnn_head_test.py --training-dir estimator/suncnn/training
"""
import argparse
import sys
import unittest

import numpy as np


class Heads(unittest.TestCase):
    def test_the_ridge_head_recovers_a_linear_law(self):
        rng = np.random.default_rng(1)
        x = rng.normal(size=(500, 3)) * [1.0, 5.0, 0.2] + [0.0, 2.0, -1.0]
        y = 0.5 + x @ np.array([2.0, -0.3, 4.0])
        pred = H.Head(x, y, 1e-6)(x)
        self.assertLess(np.max(np.abs(pred - y)), 1e-3)

    def test_the_logistic_head_ranks_what_its_signal_says(self):
        rng = np.random.default_rng(2)
        x = rng.normal(size=(2000, 2))
        y = (rng.random(2000) < 1 / (1 + np.exp(-(3 * x[:, 0] - 2)))).astype(float)
        score = H.Head(x, y, 0.1, logistic=True)(x)
        self.assertGreater(H.auc(score, y > 0), 0.85)
        # Worthless second signal: a much smaller weight than the first.
        head = H.Head(x, y, 0.1, logistic=True)
        self.assertGreater(abs(head.w[1]), 5 * abs(head.w[2]))

    def test_one_class_gives_a_finite_constant(self):
        x = np.random.default_rng(3).normal(size=(20, 4))
        score = H.Head(x, np.zeros(20), 1.0, logistic=True)(x)
        self.assertTrue(np.all(np.isfinite(score)))
        self.assertEqual(len(set(np.round(score, 12))), 1)

    def test_a_drive_is_scored_by_a_head_that_never_saw_it(self):
        rng = np.random.default_rng(4)
        x = rng.normal(size=(400, 2))
        y = x[:, 0] + 0.1 * rng.normal(size=400)
        scen = np.array([f"drive{i % 8}" for i in range(400)])
        base = H.out_of_fold(x, y, scen, 1.0, False)
        # drive0 and drive4 form one fold; changing their answers leaves their scores alone.
        fold = (scen == "drive0") | (scen == "drive4")
        y2 = y.copy()
        y2[fold] += 100.0
        moved = H.out_of_fold(x, y2, scen, 1.0, False)
        np.testing.assert_allclose(moved[fold], base[fold], atol=1e-9)
        self.assertGreater(np.max(np.abs(moved[~fold] - base[~fold])), 1.0)

    def test_the_rule_flags_nine_in_ten_gross_errors_in_every_band(self):
        rng = np.random.default_rng(5)
        n = 3000
        tan2 = np.tan(np.radians(rng.uniform(5, 80, n))) ** 2
        raw = rng.uniform(0.05, 1.0, n) + 0.2 * np.sqrt(tan2)
        err = np.where(rng.random(n) < raw / 3, 90.0, 5.0)
        tau = M.flag_threshold(err, raw, tan2)
        band = M.elevation_band(tan2)
        for b in np.unique(band):
            gross = (err > 45) & (band == b)
            if gross.sum() >= 10:
                # 90 % up to one frame (the percentile interpolates between frames)
                self.assertGreaterEqual(np.mean(raw[gross] > tau), 0.9 - 1.0 / gross.sum())
        scale, threshold = M.calibrate(err, raw, tan2)
        self.assertAlmostEqual(threshold, min(scale * tau, 3.0))


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--training-dir", required=True)
    args, rest = ap.parse_known_args()
    sys.path.insert(0, args.training_dir)
    import sun_cnn_head as H  # noqa: E402
    import sun_cnn_model as M  # noqa: E402
    unittest.main(argv=[sys.argv[0]] + rest)
