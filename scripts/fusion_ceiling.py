#!/usr/bin/env python3
"""What an attitude filter can take off a VO run's final drift, given VO's own attitude error
(issue 19, docs/experiment.md "What a filter can gain").

Reads the ground truth and a pure VO run of one route (KITTI pose files of the same frames, e.g.
`sunvo_experiment --write-poses`: route_<id>_gt.txt and route_<id>_run0.txt) and re-chains VO's
own relative translations with a corrected attitude, p_k = p_k-1 + C_w,k-1 t_k-1,k (the fusion
changes a run's position only through its attitude: re-chaining a fused run's attitude this way
gives its final position within a few centimetres). It prints:
  - oracles: VO re-chained with the true attitude, the true tilt only (VO's heading kept), the
    true heading only (VO's tilt kept) and VO's mean per-frame attitude drift in its camera (in
    hindsight) taken out: what perfect absolute attitude, or a perfectly known steady drift, is
    worth on this route;
  - a causal filter on VO's true attitude error e_w (C_w,true = Exp(e_w) C_w,vo), a random walk
    of q_tilt across the world's up and q_heading about it per frame (with --rate-sigma-deg also
    a steady drift of VO's attitude in its camera as a state), fed every --every frames
    with simulated measurements of the experiment's error models (docs/experiment.md,
    docs/vertical.md): "up" with --vertical-sigma-deg per axis, 10 % turned by 8 deg, half the
    frames without one; a Sun-CNN-like azimuth with --sun-sigma-deg, 10 % uniform outliers,
    reported sigma --sun-reported-deg, gate |innovation| < 45.6 deg (the cosine gate 0.3). The
    azimuth is taken as the rotation about the camera's y axis (its coupling with the tilt under
    an elevated sun is left out). Over the grid of (q_tilt, q_heading) it prints the cell with
    the lowest final drift, the one with the lowest rot. ARMSE and the one whose smaller gain of
    the two is largest, each picked with the truth: an oracle-tuned filter, so these cells are
    what a random-walk filter of this kind can reach at best (somewhat optimistic, as the best
    of noisy means), not results.
Means over --seeds noise draws; change against pure VO re-chained. Pure Python, no
dependencies. Usage: fusion_ceiling.py GT.txt VO.txt [--up 0,-1,0]"""
import argparse
import math
import random

# The pose files' reader and the small rotation helpers are pose_error_split.py's (this folder).
from pose_error_split import dot, load, log_so3, transpose
from pose_error_split import mul as mat_mul

DEG = math.pi / 180.0


# 3-vectors and 3x3 matrices as lists
def add(a, b):
    return [x + y for x, y in zip(a, b)]


def sub(a, b):
    return [x - y for x, y in zip(a, b)]


def scale(a, s):
    return [x * s for x in a]


def cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def norm(a):
    return math.sqrt(dot(a, a))


def mat_vec(m, v):
    return [dot(row, v) for row in m]


def exp_so3(w):
    th = norm(w)
    if th < 1e-12:
        return [[1.0, -w[2], w[1]], [w[2], 1.0, -w[0]], [-w[1], w[0], 1.0]]
    k = scale(w, 1.0 / th)
    s, c = math.sin(th), 1.0 - math.cos(th)
    kx = [[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]]
    kk = mat_mul(kx, kx)
    return [[(1.0 if i == j else 0.0) + s * kx[i][j] + c * kk[i][j] for j in range(3)]
            for i in range(3)]


class Route:
    def __init__(self, gt_path, vo_path, up):
        self.gt = load(gt_path)
        self.vo = load(vo_path)
        if len(self.gt) != len(self.vo):
            raise SystemExit(f"{vo_path}: {len(self.vo)} poses, the ground truth has {len(self.gt)}")
        self.n = len(self.gt)
        self.up = scale(up, 1.0 / norm(up))
        # VO's translation of each step in its previous camera, and its world attitude error
        # e_k with C_w,true = Exp(e_k) C_w,vo
        self.steps = [mat_vec(transpose(self.vo[k - 1][0]), sub(self.vo[k][1], self.vo[k - 1][1]))
                      for k in range(1, self.n)]
        self.err = [log_so3(mat_mul(g[0], transpose(v[0]))) for g, v in zip(self.gt, self.vo)]

    def metrics(self, corrections):
        """Final drift and rot. ARMSE of VO with C_w,k = Exp(c_k) C_w,vo,k (estimator/metrics)."""
        p = list(self.vo[0][1])
        theta = 0.0
        for k in range(self.n):
            C = mat_mul(exp_so3(corrections[k]), self.vo[k][0])
            theta += norm(log_so3(mat_mul(C, transpose(self.gt[k][0]))))
            if k + 1 < self.n:
                p = add(p, mat_vec(C, self.steps[k]))
        return norm(sub(p, self.gt[-1][1])), theta / self.n / math.sqrt(3.0)

    def heading_part(self, w):
        return scale(self.up, dot(w, self.up))


def kalman_update(x, P, h_rows, y, r_var):
    """x, P (n states) updated by the rows h_rows (n entries each; measurement y, each row's
    variance r_var): returns the new (x, P) and the innovation's squared Mahalanobis norm, for one
    or two rows; None where the innovation covariance is not positive definite."""
    n = len(x)
    Ph = [mat_vec(P, h) for h in h_rows]  # P h_i
    m = len(h_rows)
    S = [[dot(h_rows[i], Ph[j]) + (r_var if i == j else 0.0) for j in range(m)] for i in range(m)]
    det = S[0][0] if m == 1 else S[0][0] * S[1][1] - S[0][1] * S[1][0]
    if not det > 0.0 or not S[0][0] > 0.0:
        return None
    if m == 1:
        Si = [[1.0 / S[0][0]]]
    else:
        Si = [[S[1][1] / det, -S[0][1] / det], [-S[1][0] / det, S[0][0] / det]]
    nis = sum(y[i] * Si[i][j] * y[j] for i in range(m) for j in range(m))
    # K = P H^T S^-1 (n x m)
    K = [[sum(Ph[j][r] * Si[j][i] for j in range(m)) for i in range(m)] for r in range(n)]
    x_new = [x[r] + sum(K[r][i] * y[i] for i in range(m)) for r in range(n)]
    P_new = [[P[r][c] - sum(K[r][i] * Ph[i][c] for i in range(m)) for c in range(n)]
             for r in range(n)]
    P_new = [[0.5 * (P_new[r][c] + P_new[c][r]) for c in range(n)] for r in range(n)]
    return x_new, P_new, nis


def propagate_rate(x, P, G):
    """One frame of the drift-rate model: e <- e + G b (G = C_w,c of VO's camera: the steady drift
    b is VO's, in its camera), x = (e, b), P <- F P F^T with F = [[I, G], [0, I]]."""
    e, b = x[:3], x[3:]
    x = add(e, mat_vec(G, b)) + b
    Pee = [row[:3] for row in P[:3]]
    Peb = [row[3:] for row in P[:3]]
    Pbb = [row[3:] for row in P[3:]]
    GPbb = mat_mul(G, Pbb)
    GPbe = mat_mul(G, transpose(Peb))
    new_ee = [[Pee[i][j] + GPbe[i][j] + GPbe[j][i] + dot(GPbb[i], G[j]) for j in range(3)]
              for i in range(3)]
    new_eb = [[Peb[i][j] + GPbb[i][j] for j in range(3)] for i in range(3)]
    P = [new_ee[i] + new_eb[i] for i in range(3)] + \
        [[new_eb[j][i] for j in range(3)] + Pbb[i] for i in range(3)]
    return x, P


def run_filter(route, q_tilt, q_heading, args, use_up, use_sun, seed, rate_sigma=0.0):
    """The causal filter over the route; rate_sigma > 0 (deg/frame) adds a steady drift of VO's
    attitude in its camera, b, to the state (prior N(0, rate_sigma^2) per axis, a walk of
    --q-rate-deg per frame): e_k = e_k-1 + C_w,c,k b, so that the correction keeps moving between
    measurements the way VO's error does."""
    rng = random.Random(seed)
    u = route.up
    n = 6 if rate_sigma > 0.0 else 3
    Q = [[0.0] * n for _ in range(n)]
    for i in range(3):
        for j in range(3):
            Q[i][j] = ((q_tilt * DEG) ** 2 * ((1.0 if i == j else 0.0) - u[i] * u[j]) +
                       (q_heading * DEG) ** 2 * u[i] * u[j])
    for i in range(3, n):
        Q[i][i] = (args.q_rate_deg * DEG) ** 2
    a = cross(u, [1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else cross(u, [0.0, 0.0, 1.0])
    a = scale(a, 1.0 / norm(a))
    pad = [0.0] * (n - 3)
    h_up = [a + pad, cross(u, a) + pad]
    s0 = (args.initial_sigma_deg * DEG) ** 2
    P = [[(s0 if i < 3 else (rate_sigma * DEG) ** 2) if i == j else 0.0 for j in range(n)]
         for i in range(n)]
    x = [0.0] * n
    out = [[0.0, 0.0, 0.0]]
    for k in range(1, route.n):
        if n == 6:
            x, P = propagate_rate(x, P, route.vo[k][0])
        P = [[P[i][j] + Q[i][j] for j in range(n)] for i in range(n)]
        if k % args.every == 0:
            # every variate is drawn each time, so that the two sources' sequences do not interact
            v_drop, v_out, v_ang = rng.random(), rng.random(), rng.uniform(0.0, 2.0 * math.pi)
            v_noise = [rng.gauss(0.0, args.vertical_sigma_deg * DEG) for _ in range(2)]
            s_out, s_uniform = rng.random(), rng.uniform(-math.pi, math.pi)
            s_noise = rng.gauss(0.0, args.sun_sigma_deg * DEG)
            left = sub(route.err[k], x[:3])
            if use_up and v_drop >= 0.5:
                nv = v_noise if v_out >= 0.1 else [8 * DEG * math.cos(v_ang), 8 * DEG * math.sin(v_ang)]
                y = [dot(h[:3], left) + nv[i] for i, h in enumerate(h_up)]
                update = kalman_update(x, P, h_up, y, (args.vertical_sigma_deg * DEG) ** 2)
                if update is not None and update[2] < 16.3:
                    x, P = update[0], update[1]
                    left = sub(route.err[k], x[:3])
            if use_sun:
                h = [row[1] for row in route.vo[k][0]] + pad  # the camera's y axis in the world
                y = dot(h[:3], left) + (s_noise if s_out >= 0.1 else s_uniform)
                update = kalman_update(x, P, [h], [y], (args.sun_reported_deg * DEG) ** 2)
                if update is not None and abs(y) < 45.6 * DEG and update[2] < 16.3:
                    x, P = update[0], update[1]
        out.append(x[:3])
    return route.metrics(out)


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("gt")
    parser.add_argument("vo")
    parser.add_argument("--up", default="0,-1,0", help="the world's up (KITTI's first camera: 0,-1,0)")
    parser.add_argument("--every", type=int, default=5, help="a measurement every N-th frame")
    parser.add_argument("--seeds", type=int, default=10, help="noise draws per grid cell")
    parser.add_argument("--initial-sigma-deg", type=float, default=0.1)
    parser.add_argument("--vertical-sigma-deg", type=float, default=1.0)
    parser.add_argument("--sun-sigma-deg", type=float, default=12.0)
    parser.add_argument("--sun-reported-deg", type=float, default=14.3)
    parser.add_argument("--q-tilt", default="0.002,0.005,0.01,0.02,0.05,0.1,0.2",
                        help="grid of the tilt walk, deg/frame")
    parser.add_argument("--q-heading", default="0.002,0.005,0.01,0.02,0.05,0.1,0.2",
                        help="grid of the heading walk, deg/frame")
    parser.add_argument("--rate-sigma-deg", default="0",
                        help="grid of the prior sigma of a steady drift of VO's attitude in its "
                        "camera, deg/frame, a state of the filter (0: none)")
    parser.add_argument("--q-rate-deg", type=float, default=0.0,
                        help="random walk of that drift, deg/frame per frame")
    parser.add_argument("--sources", default="up,sun,up+sun",
                        help="which of the filters to run: up, sun, up+sun (none: the oracles only)")
    args = parser.parse_args()
    route = Route(args.gt, args.vo, [float(v) for v in args.up.split(",")])
    zero = [[0.0, 0.0, 0.0]] * route.n
    base = route.metrics(zero)
    print(f"{args.vo}: {route.n} frames; pure VO re-chained: final drift {base[0]:.2f} m, "
          f"rot. ARMSE {base[1] * 1e3:.2f}e-3")

    def change(drift, rot):
        return (f"{drift:6.2f} m ({100 * (drift / base[0] - 1):+4.0f} %), rot. ARMSE "
                f"{rot * 1e3:6.2f}e-3 ({100 * (rot / base[1] - 1):+4.0f} %)")

    heading = [route.heading_part(e) for e in route.err]
    tilt = [sub(e, h) for e, h in zip(route.err, heading)]
    print(f"  oracle, true attitude:     {change(*route.metrics(route.err))}")
    print(f"  oracle, true tilt only:    {change(*route.metrics(tilt))}")
    print(f"  oracle, true heading only: {change(*route.metrics(heading))}")
    # VO's steady drift in hindsight: the mean per-frame change of its attitude error in its camera
    # (e_k - e_k-1 = C_w,c,k rho), taken out from the first frame on
    rate = [0.0, 0.0, 0.0]
    for k in range(1, route.n):
        step = mat_vec(transpose(route.vo[k][0]), sub(route.err[k], route.err[k - 1]))
        rate = add(rate, scale(step, 1.0 / (route.n - 1)))
    steady = [[0.0, 0.0, 0.0]]
    for k in range(1, route.n):
        steady.append(add(steady[-1], mat_vec(route.vo[k][0], rate)))
    print(f"  oracle, VO's mean rate ({', '.join(f'{v / DEG:+.4f}' for v in rate)} deg/frame in "
          f"the camera) taken out: {change(*route.metrics(steady))}")
    q_tilts = [float(v) for v in args.q_tilt.split(",")]
    q_headings = [float(v) for v in args.q_heading.split(",")]
    rates = [float(v) for v in args.rate_sigma_deg.split(",")]
    wanted = args.sources.split(",")
    for name, use_up, use_sun in (("up", True, False), ("sun", False, True), ("up + sun", True, True)):
        if name.replace(" ", "") not in wanted:
            continue
        cells = []
        for qt in q_tilts:
            for qh in (q_headings if use_sun else [min(q_headings)]):
                for rate in rates:
                    runs = [run_filter(route, qt, qh, args, use_up, use_sun, s, rate)
                            for s in range(1, args.seeds + 1)]
                    drift = sum(r[0] for r in runs) / len(runs)
                    spread = math.sqrt(sum((r[0] - drift) ** 2 for r in runs) / len(runs))
                    rot = sum(r[1] for r in runs) / len(runs)
                    cells.append((drift, spread, rot, qt, qh, rate))
        best = min(cells)
        best_rot = min(cells, key=lambda c: c[2])
        # the cell whose smaller gain is largest: what a target on both numbers can get
        best_both = min(cells, key=lambda c: max(c[0] / base[0], c[2] / base[1]))

        def cell(c):
            rate = f" rate {c[5]:5.3f}" if len(rates) > 1 or c[5] > 0.0 else ""
            return f"q_tilt {c[3]:5.3f} q_heading {c[4]:5.3f}{rate} deg/frame: {change(c[0], c[2])}"
        print(f"  {name:8s} best drift:    {cell(best)}, drift std over the draws {best[1]:.2f} m")
        print(f"  {name:8s} best rotation: {cell(best_rot)}")
        print(f"  {name:8s} best both:     {cell(best_both)}")

if __name__ == "__main__":
    main()
