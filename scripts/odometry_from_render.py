#!/usr/bin/env python3
"""A sunvo_render drive as a KITTI odometry sequence: a world without gravity.

A render is a KITTI raw drive (ENU world from its OXTS files). KITTI odometry sequences, and many
users' own recordings, give poses relative to the first camera instead, whose tilt against gravity
nobody measured. This writes such a sequence from a render, so that what the estimator does there
(e.g. the vertical cue's world-up alignment, docs/vertical.md) can be measured on images:

    python3 scripts/odometry_from_render.py RENDER_SYNC_DIR OUT_DIR

RENDER_SYNC_DIR: the render's *_sync folder. OUT_DIR gets calib.txt (P0..P3 from
calib_cam_to_cam.txt), times.txt (seconds from the first frame), poses.txt (gt/poses_cam0.txt),
sun_cam.csv (gt/sun_cam0.csv) and image_0..image_3 with links to the render's PNGs named
000000.png, ... Nothing is copied. Standard library only.
"""
import datetime
import os
import sys


def fail(msg):
    sys.stderr.write("odometry_from_render: " + msg + "\n")
    sys.exit(1)


def rect_projections(path):
    out = {}
    with open(path) as f:
        for n, line in enumerate(f, 1):
            key, _, rest = line.partition(":")
            if key.startswith("P_rect_0"):
                values = rest.split()
                if len(values) != 12:
                    fail(f"{path}:{n}: field '{key}': expected 12 numbers, got {len(values)}")
                out[int(key[-1])] = values
    for cam in range(4):
        if cam not in out:
            fail(f"{path}: field 'P_rect_0{cam}' missing")
    return out


def seconds(path):
    times = []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            text = line.strip()
            if not text:
                continue
            day, clock = text.split(" ")
            whole, _, frac = clock.partition(".")
            try:
                t = datetime.datetime.strptime(day + " " + whole, "%Y-%m-%d %H:%M:%S")
            except ValueError:
                fail(f"{path}:{n}: not a timestamp: '{text}'")
            times.append(t.timestamp() + float("0." + (frac or "0")))
    if not times:
        fail(f"{path}: no timestamps")
    return [t - times[0] for t in times]


def main():
    if len(sys.argv) != 3:
        fail("usage: odometry_from_render.py RENDER_SYNC_DIR OUT_DIR")
    src, out = os.path.abspath(sys.argv[1]), sys.argv[2]
    calib = rect_projections(os.path.join(os.path.dirname(src), "calib_cam_to_cam.txt"))
    times = seconds(os.path.join(src, "image_00", "timestamps.txt"))
    os.makedirs(out, exist_ok=True)
    with open(os.path.join(out, "calib.txt"), "w") as f:
        for cam in range(4):
            f.write(f"P{cam}: " + " ".join(calib[cam]) + "\n")
    with open(os.path.join(out, "times.txt"), "w") as f:
        f.writelines(f"{t:.6e}\n" for t in times)
    for name, target in (("poses.txt", "gt/poses_cam0.txt"), ("sun_cam.csv", "gt/sun_cam0.csv")):
        path = os.path.join(src, target)
        if not os.path.exists(path):
            fail(f"{path}: missing")
        with open(path) as f_in, open(os.path.join(out, name), "w") as f_out:
            f_out.write(f_in.read())
    for cam in range(4):
        images = os.path.join(src, f"image_0{cam}", "data")
        if not os.path.isdir(images):
            continue
        names = sorted(n for n in os.listdir(images) if n.endswith(".png"))
        if len(names) != len(times):
            fail(f"{images}: {len(names)} images for {len(times)} timestamps")
        dst = os.path.join(out, f"image_{cam}")
        os.makedirs(dst, exist_ok=True)
        for k, name in enumerate(names):
            link = os.path.join(dst, f"{k:06d}.png")
            if os.path.lexists(link):
                os.remove(link)
            os.symlink(os.path.join(images, name), link)
    print(f"{out}: {len(times)} frames, world = the first camera")


if __name__ == "__main__":
    main()
