#!/usr/bin/env python3
"""Properties of sun_cnn_train.augment, the training batch's augmentation: shapes and types, the
input's range, the horizontal flip mirroring the azimuth, and the synthesised images without sun
cues getting target 0. Needs numpy, cv2 and torch (Debian's python3-torch).

    sun_cnn_augment_test.py --training-dir estimator/suncnn/training
"""
import argparse
import sys
import unittest

import numpy as np

N = 64


def gradient_batch(load_h, load_w):
    """Images bright on the left and dark on the right, every channel alike."""
    ramp = np.linspace(255, 0, load_w, dtype=np.float32)
    img = np.broadcast_to(ramp[None, :, None], (load_h, load_w, 3))
    return np.repeat(img[None].astype(np.uint8), N, axis=0)


class Augment(unittest.TestCase):
    def run_batch(self, channels, seed=7):
        t = np.tile(np.array([[0.0, 1.0]], np.float32), (N, 1))  # az = +90 deg: (cos, sin)
        u8 = gradient_batch(T.LOAD_H, T.LOAD_W)
        return T.augment(u8, t, np.random.default_rng(seed), channels, 0.75)

    def test_shapes_types_and_range(self):
        for channels in (3, 1):
            x, t, deg = self.run_batch(channels)
            self.assertEqual(tuple(x.shape), (N, channels, T.IN_H, T.IN_W))
            self.assertEqual(x.dtype, T.torch.float32)
            self.assertEqual(tuple(t.shape), (N, 2))
            self.assertEqual(tuple(deg.shape), (N,))
            self.assertTrue(bool(T.torch.isfinite(x).all()))
            lo, hi = (0.0 - T.MEAN) / T.STD, (1.0 - T.MEAN) / T.STD  # pixel 0 and 255
            self.assertGreaterEqual(float(x.min()), lo - 1e-5)
            self.assertLessEqual(float(x.max()), hi + 1e-5)

    def test_the_flip_mirrors_the_azimuth(self):
        x, t, deg = self.run_batch(3)
        left = x[:, :, :, : T.IN_W // 4].mean((1, 2, 3))
        right = x[:, :, :, -T.IN_W // 4:].mean((1, 2, 3))
        flipped = (left < right).numpy()
        cues = deg.numpy() == 0
        self.assertGreater(int((flipped & cues).sum()), 10)   # both kinds occur in 64 images
        self.assertGreater(int((~flipped & cues).sum()), 10)
        for i in np.nonzero(cues)[0]:
            self.assertAlmostEqual(float(t[i, 0]), 0.0, places=6)
            self.assertAlmostEqual(float(t[i, 1]), -1.0 if flipped[i] else 1.0, places=6, msg=i)

    def test_images_without_sun_cues_have_target_zero(self):
        for seed in range(4):  # 5 % of a batch: some seeds draw none
            x, t, deg = self.run_batch(3, seed)
            for i in np.nonzero(deg.numpy())[0]:
                self.assertEqual(t[i].abs().sum().item(), 0.0)

    def test_the_same_seed_gives_the_same_batch(self):
        a, b = self.run_batch(1, 3), self.run_batch(1, 3)
        for u, v in zip(a, b):
            self.assertTrue(bool(T.torch.equal(u, v)))


if __name__ == "__main__":
    ap = argparse.ArgumentParser()
    ap.add_argument("--training-dir", required=True)
    a, rest = ap.parse_known_args()
    sys.path.insert(0, a.training_dir)
    import sun_cnn_train as T  # noqa: E402
    unittest.main(argv=[sys.argv[0]] + rest)
