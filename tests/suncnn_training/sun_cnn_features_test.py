#!/usr/bin/env python3
"""Sun-CNN's feature term in the training tools (sun_cnn_model): the training features' Gaussian,
the distance d, the weakness max(0, -ln d), the gain's choice on validation rows and the JSON the
C++ estimator reads. Needs numpy only (sun_cnn_model imports torch: Debian's python3-torch).

    sun_cnn_features_test.py --training-dir estimator/suncnn/training
"""
import argparse
import json
import sys
import unittest

import numpy as np


def features(rng, n, scales, members=2):
    """[members, n, F] Gaussian features with the given per-axis std, rotated by a fixed basis."""
    f = len(scales)
    q, _ = np.linalg.qr(np.random.default_rng(0).normal(size=(f, f)))
    z = rng.normal(size=(members, n, f)) * np.asarray(scales)
    return z @ q.T + 3.0


class FeaturePrior(unittest.TestCase):
    def setUp(self):
        self.scales = np.concatenate([np.linspace(5, 2, M.FEATURE_PCS), np.full(8, 0.1)])
        self.train = features(np.random.default_rng(1), 4000, self.scales)
        self.prior = M.fit_feature_prior(self.train)

    def test_the_training_features_lie_at_distance_one(self):
        p = self.prior
        self.assertEqual(p["axes"].shape, (2, M.FEATURE_PCS, len(self.scales)))
        for m in range(2):
            np.testing.assert_allclose(p["axes"][m] @ p["axes"][m].T, np.eye(M.FEATURE_PCS),
                                       atol=1e-9)  # orthonormal rows
            np.testing.assert_allclose(np.sort(p["variances"][m])[::-1],
                                       self.scales[:M.FEATURE_PCS] ** 2, rtol=0.1)
        # np.cov divides by n - 1: the training rows' mean d is (n - 1) / n.
        self.assertAlmostEqual(float(M.feature_distance(p, self.train).mean()), 1.0, places=3)
        fresh = features(np.random.default_rng(2), 4000, self.scales)
        self.assertAlmostEqual(float(M.feature_distance(p, fresh).mean()), 1.0, delta=0.05)

    def test_weak_features_lie_near_the_mean(self):
        weak = features(np.random.default_rng(3), 500, self.scales * 0.1)
        d = M.feature_distance(self.prior, weak)
        self.assertLess(float(np.median(d)), 0.05)
        np.testing.assert_allclose(M.feature_weakness(d), -np.log(d))
        np.testing.assert_array_equal(M.feature_weakness(np.array([1.0, 4.0, 0.0])),
                                      [0.0, 0.0, -np.log(1e-12)])

    def test_the_json_round_trip_keeps_the_distance(self):
        j = json.loads(json.dumps(M.feature_prior_json(self.prior)))
        self.assertEqual((j["components"], j["features"], len(j["members"])),
                         (M.FEATURE_PCS, len(self.scales), 2))
        back = M.feature_prior_from_json(j)
        x = features(np.random.default_rng(4), 200, self.scales)
        np.testing.assert_allclose(M.feature_distance(back, x), M.feature_distance(self.prior, x),
                                   rtol=1e-3)

    def test_the_gain_follows_what_the_weakness_says(self):
        rng = np.random.default_rng(5)
        n = 4000
        raw = rng.uniform(0.2, 0.6, n)
        tan2 = np.zeros(n)
        weak = rng.exponential(1.0, n)
        gross = rng.random(n) < 0.05 + 0.25 * (weak > 2.0)  # the weak frames fail more often
        err = np.where(gross, 90.0, rng.normal(0, 8, n))
        gain, scale, threshold = M.calibrate_features(err, raw, tan2, weak)
        self.assertGreater(gain, 0.0)
        self.assertGreater(scale, 0.0)
        # A weakness the same for every frame changes no ranking and earns no gain.
        gain0, _, _ = M.calibrate_features(err, raw, tan2, np.ones(n))
        self.assertEqual(gain0, 0.0)


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--training-dir", required=True)
    a, rest = ap.parse_known_args()
    sys.path.insert(0, a.training_dir)
    import sun_cnn_model as M  # noqa: E402
    unittest.main(argv=[sys.argv[0]] + rest)
