#!/usr/bin/env python3
"""Where the vertical cue's segments disagree with the true up: the inlier segments of
`sunvo_vertical_eval --segments-csv FILE`, binned by where they lie.

Each segment's interpretation plane should contain the true up; its signed angle from it
(true_deg) is the segment's own error. A pitch error of the camera would make that angle grow
with the segment's column x0 across the whole image; a segment error of the detector shows as
a pattern in some region only. Prints the length-weighted mean true_deg per region: wholly
above the principal row, across it, wholly below it, times five bands of x0, and for the
segments above the row the same by length. Usage:

  vertical_segment_bias.py SEGMENTS.csv --cv ROW_PX [--set NAME]

--cv: the camera's principal row in pixels (the KITTI rig of the renders: 172.854)."""
import argparse
import csv
import sys

X0_BANDS = [(-10.0, -0.4), (-0.4, -0.2), (-0.2, 0.2), (0.2, 0.4), (0.4, 10.0)]
LENGTH_BANDS = [(0.0, 50.0), (50.0, 80.0), (80.0, 130.0), (130.0, 1e9)]
FIELDS = ("inlier", "true_deg", "x0", "length_px", "va", "vb")


def load(path, only_set):
    rows = []
    with open(path, newline="") as f:
        reader = csv.DictReader(f)
        missing = [k for k in FIELDS if k not in (reader.fieldnames or [])]
        if missing:
            raise ValueError(f"{path}: no column {missing[0]} (not a --segments-csv file)")
        for line, r in enumerate(reader, start=2):
            if only_set and r.get("set") != only_set:
                continue
            try:
                row = {k: float(r[k]) for k in FIELDS}
            except (TypeError, ValueError):
                bad = next(k for k in FIELDS if not _is_number(r.get(k)))
                raise ValueError(f"{path}:{line}: field '{bad}': not a number: {r.get(bad)!r}")
            if row["inlier"] == 1.0:
                rows.append(row)
    return rows


def _is_number(text):
    try:
        float(text)
        return True
    except (TypeError, ValueError):
        return False


def weighted_mean(rows):
    w = sum(r["length_px"] for r in rows)
    return sum(r["length_px"] * r["true_deg"] for r in rows) / w if w > 0 else float("nan")


def region(r, cv):
    top, bottom = min(r["va"], r["vb"]), max(r["va"], r["vb"])
    if bottom < cv:
        return "above"
    if top > cv:
        return "below"
    return "across"


def cell(rows):
    return f"{len(rows):5d} {weighted_mean(rows):+.3f}" if rows else "    0    -  "


def main():
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("segments")
    p.add_argument("--cv", type=float, required=True, help="principal row, px")
    p.add_argument("--set", default="", help="only this set's segments")
    a = p.parse_args()
    try:
        rows = load(a.segments, a.set)
    except (OSError, ValueError) as e:
        print(f"vertical_segment_bias: {e}", file=sys.stderr)
        return 1
    if not rows:
        print(f"vertical_segment_bias: {a.segments}: no inlier segments", file=sys.stderr)
        return 1
    print(f"{len(rows)} inlier segments, length-weighted mean angle from the true up "
          f"{weighted_mean(rows):+.3f} deg")
    head = " | ".join(f"x0 {lo:+.1f}..{hi:+.1f}".replace("+10.0", "").replace("-10.0", "")
                      for lo, hi in X0_BANDS)
    print(f"count, mean deg  | {head}")
    for name in ("above", "across", "below"):
        cells = [cell([r for r in rows if region(r, a.cv) == name and lo <= r["x0"] < hi])
                 for lo, hi in X0_BANDS]
        print(f"{name:16s} | " + " | ".join(cells))
    print("above, by length:")
    for lo, hi in LENGTH_BANDS:
        cells = [cell([r for r in rows if region(r, a.cv) == "above" and lo <= r["length_px"] < hi
                       and xl <= r["x0"] < xh]) for xl, xh in X0_BANDS]
        label = f"{lo:.0f}-{hi:.0f} px" if hi < 1e9 else f">= {lo:.0f} px"
        print(f"  {label:14s} | " + " | ".join(cells))
    return 0


if __name__ == "__main__":
    sys.exit(main())
