#!/usr/bin/env python3
"""One estimate (pure VO unless --estimate names another) under two option sets over many seeds of
the simulated routes, compared pair by pair.

One route's final drift swings by tens of per cent with the simulated tracks' noise draw alone
(docs/lateral_prior.md), so "no worse than today (+-5 %)" judged on one or three seeds ranks
nothing. This runs `sunvo_experiment --routes R --seed S --out OUT/<a|b>_sS [options]` for every
seed (skipping a run whose metrics are already there, so an interrupted study resumes), reads pure
VO's row (the first estimate of route_<R>_metrics.json) and prints, per route and metric, the
mean under A and B, the mean of the per-seed change B/A - 1 with its standard error, how many
seeds B makes worse by more than --worse-pct, and the ratio of the means.

  python3 scripts/seed_compare.py --experiment build/release/bin/sunvo_experiment \
      --seeds 5-14 --out /tmp/study --b="--lateral-prior 0.1 --lever-m 0.88"

With --estimate NAME (a row of the experiment's table, e.g. "VO+Sun (Sun-CNN-like) +vertical-like")
that row is compared instead, and each set's row is also compared with its own pure VO (how many
seeds it leaves worse than pure VO by more than --worse-pct). --compare-only reads OUT without
running anything. Give an option set as --b="--x 1" (an argument
that starts with -- needs the = form).
"""
import argparse
import json
import math
import os
import shlex
import subprocess
import sys
from concurrent.futures import ThreadPoolExecutor

METRICS = (
    ("final drift [m]", lambda e: e["table1"]["final_drift_m"]),
    ("rot. ARMSE [1e-3]", lambda e: 1e3 * e["table1"]["rot_armse_rad"]),
    ("t_err [%]", lambda e: e["kitti_segments"]["t_err_pct"]),
)


def parse_seeds(text):
    """'5-14' or '1,3,7' (or both mixed) -> sorted list of distinct seeds >= 0."""
    seeds = set()
    for part in text.split(","):
        part = part.strip()
        try:
            if "-" in part:
                lo, hi = (int(x) for x in part.split("-", 1))
                if lo > hi:
                    raise ValueError
                seeds.update(range(lo, hi + 1))
            else:
                seeds.add(int(part))
        except ValueError:
            raise SystemExit(f"seed_compare: --seeds: '{part}' is not a seed or a range A-B")
    if not seeds or min(seeds) < 0:
        raise SystemExit("seed_compare: --seeds: need at least one seed, all >= 0")
    return sorted(seeds)


def run_dir(out, tag, seed):
    return os.path.join(out, f"{tag}_s{seed}")


def metrics_path(out, tag, seed, route):
    return os.path.join(run_dir(out, tag, seed), f"route_{route}_metrics.json")


def run_one(args, tag, options, seed):
    """Runs one experiment unless every route's metrics exist; returns an error text or None."""
    routes = args.routes.split(",")
    if all(os.path.exists(metrics_path(args.out, tag, seed, r)) for r in routes):
        return None
    d = run_dir(args.out, tag, seed)
    os.makedirs(d, exist_ok=True)
    cmd = [args.experiment, "--routes", args.routes, "--seed", str(seed), "--out", d]
    if args.data:
        cmd += ["--data", args.data]
    cmd += shlex.split(options)
    with open(os.path.join(d, "log"), "w") as log:
        rc = subprocess.call(cmd, stdout=log, stderr=subprocess.STDOUT)
    if rc != 0:
        return f"{' '.join(cmd)} exited with {rc} (log: {os.path.join(d, 'log')})"
    return None


def read_estimate(path, name=None):
    """The metrics of the estimate called name (the first, pure VO, when None) in a metrics file."""
    try:
        with open(path) as f:
            estimates = json.load(f)["estimates"]
        if name is None:
            e = estimates[0]
        else:
            found = [e for e in estimates if e.get("name") == name]
            if not found:
                names = ", ".join(repr(e.get("name")) for e in estimates)
                raise SystemExit(f"seed_compare: {path}: no estimate '{name}' (has {names})")
            e = found[0]
        return [get(e) for _, get in METRICS]
    except FileNotFoundError:
        raise SystemExit(f"seed_compare: {path}: missing (run without --compare-only)")
    except (json.JSONDecodeError, KeyError, IndexError, TypeError, AttributeError) as e:
        raise SystemExit(f"seed_compare: {path}: not a metrics file of sunvo_experiment ({e!r})")


def summarize(values_a, values_b, worse_pct):
    """Paired statistics of B against A over seeds (lists of equal length >= 1)."""
    n = len(values_a)
    changes = [b / a - 1.0 for a, b in zip(values_a, values_b)]
    mean_change = sum(changes) / n
    se = (math.sqrt(sum((c - mean_change) ** 2 for c in changes) / (n - 1) / n)
          if n > 1 else float("nan"))
    mean_a = sum(values_a) / n
    mean_b = sum(values_b) / n
    return {
        "mean_a": mean_a,
        "mean_b": mean_b,
        "mean_change_pct": 100.0 * mean_change,
        "se_pct": 100.0 * se,
        "worse": sum(1 for c in changes if c > worse_pct / 100.0),
        "n": n,
        "ratio_of_means": mean_b / mean_a,
    }


def main(argv):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--experiment", help="sunvo_experiment binary (not needed with --compare-only)")
    p.add_argument("--data", default="", help="--data of sunvo_experiment (its default if empty)")
    p.add_argument("--routes", default="00,06")
    p.add_argument("--seeds", required=True, help="e.g. 5-14 or 1,2,3")
    p.add_argument("--out", required=True, help="folder of the runs (created)")
    p.add_argument("--a", default="", help="options of configuration A (default: none)")
    p.add_argument("--b", default="", help="options of configuration B")
    p.add_argument("--jobs", type=int, default=2, help="experiments run at once")
    p.add_argument("--worse-pct", type=float, default=5.0)
    p.add_argument("--compare-only", action="store_true")
    p.add_argument("--json", help="also write the statistics here")
    p.add_argument("--estimate", help="the table row to compare (default: the first, pure VO)")
    args = p.parse_args(argv)
    seeds = parse_seeds(args.seeds)
    if args.jobs < 1:
        raise SystemExit("seed_compare: --jobs must be >= 1")
    if not args.compare_only:
        if not args.experiment or not os.access(args.experiment, os.X_OK):
            raise SystemExit(f"seed_compare: --experiment '{args.experiment}' is not executable")
        os.makedirs(args.out, exist_ok=True)
        work = [(tag, opt, s) for s in seeds for tag, opt in (("a", args.a), ("b", args.b))]
        with ThreadPoolExecutor(max_workers=args.jobs) as pool:
            errors = [e for e in pool.map(lambda w: run_one(args, *w), work) if e]
        if errors:
            raise SystemExit("seed_compare: " + "\n".join(errors))
    print(f"A: '{args.a}'  B: '{args.b}'  seeds {args.seeds} ({len(seeds)})")
    report = {}
    for route in args.routes.split(","):
        a = [read_estimate(metrics_path(args.out, "a", s, route), args.estimate) for s in seeds]
        b = [read_estimate(metrics_path(args.out, "b", s, route), args.estimate) for s in seeds]
        report[route] = {}
        print(f"route {route}, {args.estimate or 'pure VO'}:")
        for i, (name, _) in enumerate(METRICS):
            st = summarize([x[i] for x in a], [x[i] for x in b], args.worse_pct)
            report[route][name] = st
            print(f"  {name:18s} A {st['mean_a']:8.3f}  B {st['mean_b']:8.3f}  "
                  f"change {st['mean_change_pct']:+6.1f} % (se {st['se_pct']:.1f})  "
                  f"worse by >{args.worse_pct:g} % on {st['worse']}/{st['n']}  "
                  f"ratio of means {st['ratio_of_means']:.3f}")
        if args.estimate is None:
            continue
        for tag, rows in (("a", a), ("b", b)):
            pure = [read_estimate(metrics_path(args.out, tag, s, route)) for s in seeds]
            for i, (name, _) in enumerate(METRICS):
                st = summarize([x[i] for x in pure], [x[i] for x in rows], args.worse_pct)
                report[route][f"{tag.upper()} against pure VO: {name}"] = st
                print(f"  {tag.upper()} against its pure VO, {name:18s} change "
                      f"{st['mean_change_pct']:+6.1f} % (se {st['se_pct']:.1f})  worse by "
                      f">{args.worse_pct:g} % on {st['worse']}/{st['n']}  "
                      f"ratio of means {st['ratio_of_means']:.3f}")
    if args.json:
        with open(args.json, "w") as f:
            json.dump(report, f, indent=1)
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
