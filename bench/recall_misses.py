#!/usr/bin/env python3
"""Where does screening lose dynamic recall? Splits the person-mask area that no screened box
covers, per frame of a yolo_slam_run output on a yolo_slam_synth sequence, into:

  person missed at the image edge    no box covers the person (< 5 % of their mask) and the
                                     person touches the image border (partly in view)
  person missed inside the image     no box covers the person, who is fully in view
  person partly outside the box      a box covers the person, but not all of them

Boxes are read from RUN/boxes_screened.txt (every box screened: detections plus the boxes the
tracker carried), grown by --dilation per side as the screener grows them. Also lists the
frames with the most uncovered mask area.

usage: bench/recall_misses.py SEQUENCE RUN [--dilation 0.05] [--worst 8]
  SEQUENCE  yolo_slam_synth folder (rgb.txt, masks/)
  RUN       yolo_slam_run --out folder of a run on it in mode detect or detect+geometry
Needs python3-opencv and python3-numpy (scripts/install_deps.sh installs them).
"""
import argparse
import collections
import os
import sys

try:
    import cv2
    import numpy as np
except ImportError as e:
    sys.exit(f"error: {e}; install python3-opencv and python3-numpy (scripts/install_deps.sh) "
             "and run with /usr/bin/python3")


def read_boxes(path):
    if not os.path.isfile(path):
        sys.exit(f"error: {path}: not found; run yolo_slam_run in mode detect or detect+geometry "
                 "(it writes boxes_screened.txt)")
    boxes = collections.defaultdict(list)
    with open(path) as f:
        for n, line in enumerate(f, 1):
            if line.startswith("#") or not line.strip():
                continue
            p = line.split()
            if len(p) != 9:
                sys.exit(f"error: {path}:{n}: expected 9 fields "
                         "(rgb_stamp index label x1 y1 x2 y2 score tracked)")
            boxes[round(float(p[0]), 3)].append(tuple(map(float, p[3:7])))
    return boxes


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("sequence")
    ap.add_argument("run")
    ap.add_argument("--dilation", type=float, default=0.05, help="Screening.boxDilation (0.05)")
    ap.add_argument("--worst", type=int, default=8, help="frames listed with the most uncovered area")
    a = ap.parse_args()
    rgb_txt = os.path.join(a.sequence, "rgb.txt")
    if not os.path.isfile(rgb_txt):
        sys.exit(f"error: {rgb_txt}: not found; pass a yolo_slam_synth sequence folder")
    boxes = read_boxes(os.path.join(a.run, "boxes_screened.txt"))
    area = collections.Counter()
    worst = []
    total_mask = 0
    with open(rgb_txt) as f:
        frames = [l.split() for l in f if l.strip() and not l.startswith("#")]
    for stamp, rel in frames:
        mpath = os.path.join(a.sequence, "masks", os.path.basename(rel))
        m = cv2.imread(mpath, cv2.IMREAD_GRAYSCALE)
        if m is None:
            continue
        h, w = m.shape
        cover = np.zeros((h, w), dtype=bool)
        for x1, y1, x2, y2 in boxes.get(round(float(stamp), 3), []):
            dx, dy = a.dilation * (x2 - x1), a.dilation * (y2 - y1)
            cover[max(0, int(y1 - dy)):max(0, int(y2 + dy + 1)), max(0, int(x1 - dx)):max(0, int(x2 + dx + 1))] = True
        # 255: a person; other moving objects (200, the carried box) are no detector's job.
        n, lab, st, _ = cv2.connectedComponentsWithStats((m == 255).astype(np.uint8))
        frame_out = 0
        for c in range(1, n):
            comp = lab == c
            size = int(comp.sum())
            total_mask += size
            out = int((comp & ~cover).sum())
            if out == 0:
                continue
            frame_out += out
            x, y, bw, bh = st[c, :4]
            at_edge = x <= 1 or y <= 1 or x + bw >= w - 1 or y + bh >= h - 1
            if out > 0.95 * size:
                area["person missed at the image edge" if at_edge else "person missed inside the image"] += out
            else:
                area["person partly outside the box"] += out
        worst.append((frame_out, stamp))
    uncovered = sum(area.values())
    if total_mask == 0:
        sys.exit("error: no person mask pixels in this sequence")
    print(f"{len(frames)} frames; person-mask pixels not covered by any screened box: {uncovered} "
          f"of {total_mask} ({100.0 * uncovered / total_mask:.1f} %)")
    print("| where | pixels | share of uncovered |\n|---|---|---|")
    for k in ("person missed at the image edge", "person missed inside the image", "person partly outside the box"):
        print(f"| {k} | {area[k]} | {100.0 * area[k] / max(uncovered, 1):.1f} % |")
    print("frames with the most uncovered mask area (pixels, rgb stamp):")
    for out, stamp in sorted(worst, reverse=True)[:a.worst]:
        print(f"  {out:7d}  {stamp}")


if __name__ == "__main__":
    main()
