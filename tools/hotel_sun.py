#!/usr/bin/python3
# This file is part of augocc. License: Apache-2.0.
"""The sun estimated on real footage with no truth: the CMU hotel (../shared/data/cmu_hotel, a
toy hotel lit by lamps, 101 frames of 512x480, dark background), issue 19 item 3.

Key-frame masks of the hotel in frames 0, 50 and 100 are made from the frames themselves (the
hotel is brighter than the background: a threshold, the largest component, holes filled, the
neighbouring roof at the bottom left cut off along the hotel's left wall; checked by eye in
OUT/masks_check.png). Then `augocc run` (track, sfm, clone, matte), `augocc sun`, and
`augocc composite` of a dome behind the hotel with the fixed light and with the estimated sun;
OUT/hotel_sun.png shows frames 0, 50 and 100 of both.

Usage: tools/hotel_sun.py [--augocc build/bin/augocc] [--data ../shared/data/cmu_hotel] [--out OUT]
"""
import argparse
import os
import subprocess
import sys

import cv2
import numpy as np

KEY_FRAMES = (0, 50, 100)
THRESHOLD = 21  # grey level over the background (10-20) and under the roof (25 and more)
# The neighbouring roof (frames 0 and 50): pixels below y_min and left of the line (x0, y0)-(x1, y1).
CUTS = {0: ((133, 275), (217, 480), 250), 50: ((128, 300), (128, 480), 300)}

SCENE = """%YAML:1.0
---
objects:
   -
      name: dome
      shape: dome
      behind: hotel
      distance: 0.05
      size: 0.6
      offset: [ -0.55, 0.45, 0. ]
"""


def hotel_mask(gray, frame):
    blurred = cv2.GaussianBlur(gray, (9, 9), 0)
    m = (blurred > THRESHOLD).astype(np.uint8)
    m = cv2.morphologyEx(m, cv2.MORPH_OPEN, np.ones((9, 9), np.uint8))
    n, labels, stats, _ = cv2.connectedComponentsWithStats(m)
    m = (labels == 1 + np.argmax(stats[1:, cv2.CC_STAT_AREA])).astype(np.uint8)
    m = cv2.morphologyEx(m, cv2.MORPH_CLOSE, np.ones((15, 15), np.uint8))
    outside = m.copy()
    cv2.floodFill(outside, np.zeros((m.shape[0] + 2, m.shape[1] + 2), np.uint8), (0, 0), 1)
    m[outside == 0] = 1
    if frame in CUTS:
        (x0, y0), (x1, y1), y_min = CUTS[frame]
        yy, xx = np.mgrid[0:m.shape[0], 0:m.shape[1]]
        left = (xx - x0) * (y1 - y0) - (yy - y0) * (x1 - x0) < 0
        m[(yy > y_min) & left] = 0
    return m * 255


def run(*args):
    print("+", " ".join(str(a) for a in args), flush=True)
    subprocess.run([str(a) for a in args], check=True)


def main():
    root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--augocc", default=os.path.join(root, "build", "bin", "augocc"))
    ap.add_argument("--data", default=os.path.join(root, "..", "shared", "data", "cmu_hotel"))
    ap.add_argument("--out", default="hotel_sun")
    a = ap.parse_args()
    frames = os.path.join(a.data, "frames")
    if not os.path.isdir(frames):
        sys.exit("hotel_sun: %s: no such folder (the CMU hotel frames of ../shared/data)" % frames)
    os.makedirs(os.path.join(a.out, "masks", "hotel"), exist_ok=True)
    checks = []
    for f in KEY_FRAMES:
        gray = cv2.imread(os.path.join(frames, "%04d.png" % f), cv2.IMREAD_GRAYSCALE)
        if gray is None:
            sys.exit("hotel_sun: frame %d of %s cannot be read" % (f, frames))
        m = hotel_mask(gray, f)
        cv2.imwrite(os.path.join(a.out, "masks", "hotel", "%04d.png" % f), m)
        vis = cv2.cvtColor(gray, cv2.COLOR_GRAY2BGR)
        contours, _ = cv2.findContours((m > 0).astype(np.uint8), cv2.RETR_EXTERNAL,
                                       cv2.CHAIN_APPROX_NONE)
        cv2.drawContours(vis, contours, -1, (0, 0, 255), 2)
        checks.append(vis)
    cv2.imwrite(os.path.join(a.out, "masks_check.png"), np.hstack(checks))
    shot = os.path.join(a.out, "shot")
    run(a.augocc, "--quiet", "run", "--input", frames, "--masks", os.path.join(a.out, "masks"),
        "--out-dir", shot)
    rec = os.path.join(shot, "reconstruction.yml")
    clones = os.path.join(shot, "clones.yml.gz")
    sun = os.path.join(a.out, "sun.yml")
    run(a.augocc, "sun", "--input", frames, "--reconstruction", rec, "--clones", clones,
        "--out", sun)
    with open(sun) as fh:
        text = fh.read()
    scenes = {"fixed": SCENE, "sun": SCENE + text[text.index("\nsun:") + 1:]}
    rows = []
    for name, body in scenes.items():
        path = os.path.join(a.out, "scene_%s.yml" % name)
        with open(path, "w") as fh:
            fh.write(body)
        out = os.path.join(a.out, "composite_%s" % name)
        run(a.augocc, "--quiet", "composite", "--input", frames, "--reconstruction", rec,
            "--clones", clones, "--scene", path, "--out", out)
        rows.append(np.hstack([cv2.imread(os.path.join(out, "%04d.png" % f))
                               for f in KEY_FRAMES]))
    cv2.imwrite(os.path.join(a.out, "hotel_sun.png"), np.vstack(rows))
    print("hotel_sun: %s (top: the fixed light; bottom: the estimated sun)" %
          os.path.join(a.out, "hotel_sun.png"))


if __name__ == "__main__":
    main()
