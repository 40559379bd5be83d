#!/usr/bin/python3
"""How much of the view do the people take? Per frame that has a person mask: the share of the
image the people cover, the share of ORB keypoints (OpenCV ORB, 1000 features, 8 levels) that
fall on them, and the median depth of their pixels; then the mean, median, 90th percentile and
maximum over the frames. Compares a generated sequence with a real one.

usage: bench/people_share.py SEQUENCE [--step 10]
  SEQUENCE  a yolo_slam_synth folder (masks/, one per rgb frame; > 127 = moving object) or a
            TUM folder with dynamic_mask/ (as ../shared's fr3_walking_xyz: 255 = person);
            frames are read from associations.txt, frames without a mask are skipped
  --step N  every N-th associated frame (default 10)
Needs python3-opencv and python3-numpy (scripts/install_deps.sh installs them).
"""
import argparse
import os
import sys

try:
    import cv2
    import numpy as np
except ImportError as e:
    sys.exit(f"error: {e}; install python3-opencv and python3-numpy (scripts/install_deps.sh) "
             "and run with /usr/bin/python3")


def frames(seq):
    path = os.path.join(seq, "associations.txt")
    if not os.path.isfile(path):
        sys.exit(f"error: {path} not found: SEQUENCE must be a TUM folder with associations.txt")
    mask_dir = next((d for d in ("masks", "dynamic_mask") if os.path.isdir(os.path.join(seq, d))), None)
    if mask_dir is None:
        sys.exit(f"error: {seq} has neither masks/ nor dynamic_mask/: nothing to measure")
    with open(path) as f:
        for line in f:
            parts = line.split()
            if len(parts) < 4 or line.startswith("#"):
                continue
            mask = os.path.join(seq, mask_dir, parts[0] + ".png")
            if os.path.isfile(mask):
                yield os.path.join(seq, parts[1]), os.path.join(seq, parts[3]), mask


def summary(name, values, fmt):
    v = np.asarray(values, dtype=float)
    return (f"{name}: mean {fmt % v.mean()}, median {fmt % np.median(v)}, "
            f"p90 {fmt % np.percentile(v, 90)}, max {fmt % v.max()}")


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("sequence")
    ap.add_argument("--step", type=int, default=10)
    args = ap.parse_args()
    if args.step < 1:
        sys.exit("error: --step must be >= 1")
    orb = cv2.ORB_create(1000, 1.2, 8, fastThreshold=20)
    pixel_share, keypoint_share, depth = [], [], []
    for k, (rgb_path, depth_path, mask_path) in enumerate(frames(args.sequence)):
        if k % args.step:
            continue
        img = cv2.imread(rgb_path, cv2.IMREAD_GRAYSCALE)
        mask = cv2.imread(mask_path, cv2.IMREAD_GRAYSCALE)
        dep = cv2.imread(depth_path, cv2.IMREAD_UNCHANGED)
        for p, im in ((rgb_path, img), (mask_path, mask), (depth_path, dep)):
            if im is None:
                sys.exit(f"error: cannot read {p}: missing or not an image")
        people = mask > 127
        kps = orb.detect(img, None)
        on = sum(1 for kp in kps if people[int(kp.pt[1]), int(kp.pt[0])])
        pixel_share.append(people.mean())
        keypoint_share.append(on / max(1, len(kps)))
        z = dep[people & (dep > 0)].astype(float) / 5000.0
        if z.size >= 100:
            depth.append(np.median(z))
    if not pixel_share:
        sys.exit(f"error: no frame of {args.sequence} has a mask")
    print(f"{args.sequence}: {len(pixel_share)} frames (every {args.step}th with a mask)")
    print(summary("  image share of the people", pixel_share, "%.3f"))
    print(summary("  ORB keypoints on the people", keypoint_share, "%.3f"))
    if depth:
        print(summary("  median depth of the people (m)", depth, "%.2f") +
              f", min {min(depth):.2f} ({len(depth)} frames with >= 100 person pixels with depth)")


if __name__ == "__main__":
    main()
