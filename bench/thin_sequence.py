#!/usr/bin/env python3
"""A TUM-layout sequence with frames dropped in bursts, as a camera feed that cannot keep up
drops them (camera rate, a ROS queue of 1, the gaps in TUM's own recordings): after each kept
frame 0-3 frames are left out (weights 3:2:1:1, about half the frames kept), drawn from --seed.

The new folder links the source's rgb/, depth/, masks/, groundtruth.txt, camera.yaml and
boxes.txt and gets its own associations.txt, so yolo_slam_run and its screening metrics run on
it as on the source.

usage: bench/thin_sequence.py SOURCE OUT [--seed 3] [--max-frames N]
  SOURCE  a folder with associations.txt (yolo_slam_synth writes one)
"""
import argparse
import os
import random
import sys

LINKED = ("rgb", "depth", "masks", "groundtruth.txt", "camera.yaml", "boxes.txt")
SKIPS = (0, 0, 0, 1, 1, 2, 3)  # frames left out after a kept one


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("source")
    ap.add_argument("out")
    ap.add_argument("--seed", type=int, default=3)
    ap.add_argument("--max-frames", type=int, default=0, help="only the first N frames of the source (0: all)")
    a = ap.parse_args()
    assoc = os.path.join(a.source, "associations.txt")
    if not os.path.isfile(assoc):
        sys.exit(f"error: {assoc}: not found; pass a TUM folder with associations.txt")
    with open(assoc) as f:
        lines = [l for l in f if l.strip() and not l.startswith("#")]
    if a.max_frames > 0:
        lines = lines[:a.max_frames]
    os.makedirs(a.out, exist_ok=True)
    for name in LINKED:
        src, dst = os.path.abspath(os.path.join(a.source, name)), os.path.join(a.out, name)
        if os.path.exists(src) and not os.path.lexists(dst):
            os.symlink(src, dst)
    rng = random.Random(a.seed)
    kept, i = [], 0
    while i < len(lines):
        kept.append(lines[i])
        i += 1 + rng.choice(SKIPS)
    with open(os.path.join(a.out, "associations.txt"), "w") as f:
        f.writelines(kept)
    print(f"{a.out}: {len(kept)} of {len(lines)} frames")


if __name__ == "__main__":
    main()
