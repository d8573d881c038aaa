"""Sun-CNN network, its exported graph and the uncertainty it reports (shared by training and
evaluation).

Model: a 5x5 stride-2 conv and three 3x3 convs (each BN, ReLU, 2x2 max-pool) on a 64x208 image
(BGR for the colour model, one grey plane for the grey model; about 13.5 M multiply-adds),
flattened (64 x 2 x 6 = 768 features), then dropout -> FC 128 -> ReLU -> dropout -> FC 2. The
output v = (c, s) is regressed onto t = (cos az, sin az), az = atan2(sun_x, sun_z), with the
squared chord ||v - t||^2 (targets on the unit circle). The minimiser of the expected chord loss
is E[t | image], whose length is the mean resultant length of the azimuth posterior: images
without sun cues are answered with a short vector.

The shipped model is an ensemble of M such nets trained from different seeds (a deep ensemble:
their disagreement is the out-of-distribution signal, which MC dropout in the head alone misses).

Export (ONNX opset 11, read by OpenCV 4.6 DNN): inputs image [1,C,64,208], mask1 [K,768],
mask2 [K,128]; output [M*K, 2]. Each member's trunk runs once, its features are repeated K
times (Concat) and multiplied by the masks (inverted dropout: entries 0 or 1/(1-p); all ones =
dropout off); rows m*K .. m*K+K-1 are member m. Row m*K (masks of ones) is member m's
deterministic answer, rows m*K+1 .. m*K+N its MC samples; the caller owns the random numbers.
"""
import numpy as np
import torch
import torch.nn as nn

IN_H, IN_W = 64, 208
MEAN, STD = 0.5, 0.25  # x = (pixel / 255 - MEAN) / STD, every channel
DROPOUT_P = 0.3
K_ROWS = 32  # rows of each member's exported head (1 deterministic + up to 31 MC samples)
FEAT, HIDDEN = 64 * 2 * 6, 128


class SunCnn(nn.Module):
    def __init__(self, channels, width=1, depth=1):
        super().__init__()
        # 64x208 -> (5x5 stride-2 conv, pool) 16x52 -> 8x26 -> 4x13 -> 2x6 (x64 channels).
        # width multiplies the channels of the first three convs (the last stays 64: FEAT);
        # depth is the number of 3x3 convs (each BN, ReLU) in each of the last three stages.
        c1, c2, c3 = 16 * width, 32 * width, 64 * width
        layers = [nn.Conv2d(channels, c1, 5, stride=2, padding=2, bias=False), nn.BatchNorm2d(c1),
                  nn.ReLU(), nn.MaxPool2d(2)]
        for a, b in ((c1, c2), (c2, c3), (c3, 64)):
            for i in range(depth):
                layers += [nn.Conv2d(a if i == 0 else b, b, 3, padding=1, bias=False),
                           nn.BatchNorm2d(b), nn.ReLU()]
            layers.append(nn.MaxPool2d(2))
        self.trunk = nn.Sequential(*layers)
        self.fc1 = nn.Linear(FEAT, HIDDEN)
        self.fc2 = nn.Linear(HIDDEN, 2)
        self.drop = nn.Dropout(DROPOUT_P)

    def features(self, x):
        return torch.flatten(self.trunk(x), 1)

    def forward(self, x):
        h = torch.relu(self.fc1(self.drop(self.features(x))))
        return self.fc2(self.drop(h))


class EnsembleExport(nn.Module):
    """The exported graph: for every member, trunk once and K masked head passes."""

    def __init__(self, members):
        super().__init__()
        self.members = nn.ModuleList(members)

    def forward(self, image, mask1, mask2):
        outs = []
        for m in self.members:
            f = torch.cat([m.features(image)] * K_ROWS, 0) * mask1
            outs.append(m.fc2(torch.relu(m.fc1(f)) * mask2))
        return torch.cat(outs, 0)


def mc_predict(members, x, samples, gen):
    """Per member: the deterministic output [n, 2] and `samples` dropout outputs [n, S, 2], with
    masks drawn as the C++ side draws them (same masks for every member)."""
    dets, samps = [], []
    with torch.no_grad():
        feats = [m.eval().features(x) for m in members]
        masks = []
        for _ in range(samples):
            m1 = (torch.rand(feats[0].shape, generator=gen) >= DROPOUT_P).float() / (1 - DROPOUT_P)
            m2 = (torch.rand((x.shape[0], HIDDEN), generator=gen) >= DROPOUT_P).float() / (1 - DROPOUT_P)
            masks.append((m1, m2))
        for m, f in zip(members, feats):
            dets.append(m.fc2(torch.relu(m.fc1(f))).numpy())
            samps.append(torch.stack([m.fc2(torch.relu(m.fc1(f * m1)) * m2) for m1, m2 in masks],
                                     1).numpy())
    return np.stack(dets, 0), np.stack(samps, 0)  # [M, n, 2], [M, n, S, 2]


def combine(dets, samps):
    """The answer and the raw spread as the C++ estimator computes them: the direction of the
    mean deterministic vector of the members; R_al = its length, R_mc = the mean resultant
    length of all M*S unit sample directions; raw sigma = sqrt(-2 ln R_mc - 2 ln R_al) (rad)."""
    v = dets.mean(0)
    u = samps / np.maximum(np.linalg.norm(samps, axis=3, keepdims=True), 1e-9)
    m, n, s, _ = u.shape
    r_mc = np.clip(np.linalg.norm(u.transpose(1, 0, 2, 3).reshape(n, m * s, 2).mean(1), axis=1),
                   1e-6, 1.0)
    r_al = np.clip(np.linalg.norm(v, axis=1), 1e-6, 1.0)
    return v, np.sqrt(-2 * np.log(r_mc) - 2 * np.log(r_al))


def sigma_of(raw, scale):
    """The reported sigma (rad) of raw spreads: scaled and clamped to [0.03, 3], as SunCnnOptions'
    sigma_min_rad / sigma_max_rad do in C++."""
    return np.clip(scale * raw, 0.03, 3.0)


def elevation_band(tan2):
    """Index of each frame's sun-elevation band in ELEVATION_BANDS_DEG (from elevation_tan2)."""
    return np.digitize(np.degrees(np.arctan(np.sqrt(tan2))), ELEVATION_BANDS_DEG[1:-1])


def flag_threshold(err_deg, raw, tan2=None):
    """calibrate()'s threshold on raw: the 10th percentile of raw over the gross (> 45 deg)
    errors (inf with fewer than 5), or with tan2 the lowest such percentile over the elevation
    bands holding at least 10 gross errors."""
    gross = np.abs(err_deg) > 45
    tau = np.percentile(raw[gross], 10) if gross.sum() >= 5 else np.inf
    if tan2 is not None:
        band = elevation_band(tan2)
        taus = [np.percentile(raw[gross & (band == b)], 10) for b in np.unique(band)
                if (gross & (band == b)).sum() >= 10]
        if taus:
            tau = min(taus)
    return tau


def calibrate(err_deg, raw, tan2=None):
    """The validity threshold and the sigma scale, from validation errors (deg) and raw sigmas
    (rad). The threshold on raw sigma flags 90 % of the gross (> 45 deg) errors (the 10th
    percentile of raw sigma over them; with fewer than 5 gross errors no frame is flagged).
    Given tan2 (elevation_tan2 of the frames), it flags 90 % of them in every sun-elevation band
    (ELEVATION_BANDS_DEG) that holds at least 10 (the lowest band threshold), so that the rule
    does not depend on how the validation drives mix high and low suns.
    The scale then makes 95 % of the frames below it fall within 2 sigma, i.e. sigma is
    calibrated on the frames the estimator calls valid, which are the ones the fusion sees.
    Returns (scale, threshold on the scaled sigma in rad)."""
    tau = flag_threshold(err_deg, raw, tan2)
    valid = raw <= tau
    if valid.sum() < 5:
        valid = np.ones_like(valid)
    scale = float(np.percentile(np.radians(np.abs(err_deg[valid])) / raw[valid], 95) / 2.0)
    return scale, float(min(scale * tau, 3.0))


# The sun's elevation as a second uncertainty signal. The higher the sun, the shorter the shadows
# and the more even the sky around the horizon: the image says less about the azimuth, and the
# network's spread does not fully know it (validation, 2026-12-02: 9 % gross errors below 30 deg
# of elevation, 62 % above 75 deg; docs/sun_cnn_calibration.md). The raw sigma becomes
#     raw' = sqrt(raw^2 + gain tan^2(min(elevation, 85 deg)))   (0 for a sun below the horizon),
# the elevation being the ephemeris's (the C++ estimator takes it from its prior, sun_c . up_c).
ELEVATION_CAP_DEG = 85.0
ELEVATION_GAINS = (0.0, 0.003, 0.01, 0.03, 0.1, 0.3, 1.0)
ELEVATION_BANDS_DEG = (0.0, 30.0, 45.0, 60.0, 90.0)  # calibrate(): 90 % flagged in each


def elevation_tan2(sun_cam):
    """tan^2 of the sun's elevation, capped at 85 deg, 0 below the horizon, from camera-frame sun
    vectors (y down). The camera's tilt from level (a few degrees on the rendered drives) is
    neglected here; the C++ estimator uses the true horizontal plane."""
    s = np.asarray(sun_cam, np.float64)
    sin_el = np.clip(-s[:, 1] / np.maximum(np.linalg.norm(s, axis=1), 1e-12), -1.0, 1.0)
    el = np.minimum(np.arcsin(sin_el), np.radians(ELEVATION_CAP_DEG))
    return np.where(el > 0, np.tan(np.maximum(el, 0.0)) ** 2, 0.0)


def with_elevation(raw, tan2, gain):
    return np.sqrt(raw ** 2 + gain * tan2)


def calibrate_elevation(err_deg, raw, tan2):
    """The elevation gain, then calibrate() on raw' with the elevation bands: the gain in
    ELEVATION_GAINS whose threshold (still flagging 90 % of the validation gross errors in every
    band) leaves the most validation frames valid; the smallest such gain on a tie. Returns
    (gain, scale, threshold)."""
    return most_valid(err_deg, tan2, ((g, with_elevation(raw, tan2, g)) for g in ELEVATION_GAINS))


def most_valid(err_deg, tan2, candidates):
    """Of (gain, raw') candidates, in order, the one whose calibrate() leaves the most frames
    valid; the first on a tie. Returns (gain, scale, threshold)."""
    best = None
    for gain, r in candidates:
        scale, threshold = calibrate(err_deg, r, tan2)
        valid = float(np.mean(sigma_of(r, scale) <= threshold))
        if best is None or valid > best[0] + 1e-12:
            best = (valid, gain, scale, threshold)
    return best[1], best[2], best[3]


# The strength of the image's features as a third uncertainty signal (docs/sun_cnn_calibration.md,
# "Distance from the training features"). Per member, the trunk's 768 features (dropout off) are
# projected on the top FEATURE_PCS principal axes of the training images' features and whitened;
#     d = mean over members of |z|^2 / FEATURE_PCS       (about 1 on the training images).
# Measured as an out-of-distribution score it fails: the held-out looks lie nearer the training
# mean than the training images, and their gross errors nearer still. Read the other way round it
# is the strength of the sun cues the trunk found, which adds to the spread where that is small:
#     raw' = sqrt(raw^2 + elevation_gain tan^2(e) + feature_gain max(0, -ln d)).
# Only weak features widen sigma; strong or unusual ones never narrow it.
FEATURE_PCS = 16
FEATURE_GAINS = (0.0, 0.03, 0.1, 0.3, 1.0)


def member_layers(net, keep):
    """Names of an exported graph's layers that keep() accepts, one per member, in member order
    (name, name_1, name_2, ...)."""
    return sorted((n for n in net.getLayerNames() if keep(n)), key=lambda n: (len(n), n))


def trunk_layers(net):
    """The per-member trunk outputs (the Flatten nodes) of an exported graph, member order."""
    return member_layers(net, lambda n: n.startswith("onnx_node!/Flatten")
                         and not n.endswith("/flatten"))


def fit_feature_prior(trunk):
    """The training features' Gaussian per member, from trunk [M, n, F]: mean [M, F], the top
    FEATURE_PCS principal axes [M, P, F] and their variances [M, P]."""
    mean = trunk.mean(1)
    axes, var = [], []
    for m in range(trunk.shape[0]):
        w, v = np.linalg.eigh(np.cov((trunk[m] - mean[m]).T))
        top = np.argsort(w)[::-1][:FEATURE_PCS]
        axes.append(v[:, top].T)
        var.append(np.maximum(w[top], 1e-12))
    return {"mean": mean, "axes": np.stack(axes), "variances": np.stack(var)}


def feature_distance(prior, trunk):
    """d per image (see above) from trunk [M, n, F]."""
    d = np.zeros(trunk.shape[1])
    for m in range(trunk.shape[0]):
        z = (trunk[m] - prior["mean"][m]) @ prior["axes"][m].T
        d += (z ** 2 / prior["variances"][m]).sum(1) / z.shape[1]
    return d / trunk.shape[0]


def feature_weakness(d):
    return np.maximum(0.0, -np.log(np.maximum(d, 1e-12)))


def calibrate_features(err_deg, raw, tan2, weakness):
    """The feature gain in FEATURE_GAINS, raw the spread with the elevation term already in it:
    the one whose calibrate() leaves the most validation frames valid (the smallest on a tie).
    Returns (gain, scale, threshold)."""
    return most_valid(err_deg, tan2,
                      ((g, np.sqrt(raw ** 2 + g * weakness)) for g in FEATURE_GAINS))


def feature_prior_json(prior):
    """The prior as the model JSON holds it (5 significant digits)."""
    def r(a):
        return [float(f"{x:.5g}") for x in np.asarray(a, np.float64).ravel()]
    return {"components": int(prior["axes"].shape[1]), "features": int(prior["axes"].shape[2]),
            "members": [{"mean": r(prior["mean"][m]), "axes": r(prior["axes"][m]),
                         "variances": r(prior["variances"][m])}
                        for m in range(prior["axes"].shape[0])]}


def feature_prior_from_json(j):
    p, f = j["components"], j["features"]
    ms = j["members"]
    return {"mean": np.array([m["mean"] for m in ms]),
            "axes": np.array([m["axes"] for m in ms]).reshape(len(ms), p, f),
            "variances": np.array([m["variances"] for m in ms])}
