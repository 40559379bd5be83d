#!/usr/bin/env python3
"""Which people get a box of their own? For every person in every frame of a yolo_slam_synth
sequence (its boxes.txt: each person's visible box and visible fraction), whether a box the run
screened (RUN/boxes_screened.txt: detections plus the boxes the tracker carried) matches that
person's visible box (IoU >= --iou), split by how much of the person is visible, and how long
the misses last (runs of consecutive frames in which the person has no box).

bench/recall_misses.py counts mask pixels under any box; a person standing behind another is
under the front person's box there, but screening keeps them static (the box's nearest depth
cluster is the front person), so this count is per person.

usage: bench/person_boxes.py SEQUENCE RUN [--iou 0.3] [--min-visible 0.3]
  SEQUENCE  yolo_slam_synth folder (boxes.txt)
  RUN       yolo_slam_run --out folder of a run on it in mode detect or detect+geometry
"""
import argparse
import collections
import os
import sys

VISIBLE_BINS = (0.2, 0.4, 0.6, 0.8, 1.01)
RUN_BINS = ((1, 1, "1"), (2, 5, "2-5"), (6, 19, "6-19"), (20, 10 ** 9, "20+"))


def read_lines(path, fields, what):
    if not os.path.isfile(path):
        sys.exit(f"error: {path}: not found; {what}")
    with open(path) as f:
        for n, line in enumerate(f, 1):
            if line.startswith("#") or not line.strip():
                continue
            p = line.split()
            if len(p) != fields:
                sys.exit(f"error: {path}:{n}: expected {fields} fields")
            yield p


def iou(a, b):
    ix = max(0.0, min(a[2], b[2]) - max(a[0], b[0]))
    iy = max(0.0, min(a[3], b[3]) - max(a[1], b[1]))
    inter = ix * iy
    union = (a[2] - a[0]) * (a[3] - a[1]) + (b[2] - b[0]) * (b[3] - b[1]) - inter
    return inter / union if union > 0 else 0.0


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("sequence")
    ap.add_argument("run")
    ap.add_argument("--iou", type=float, default=0.3, help="IoU a screened box needs with the person's visible box")
    ap.add_argument("--min-visible", type=float, default=0.3, help="people less visible than this are left out")
    a = ap.parse_args()
    people = collections.defaultdict(list)  # rgb stamp -> (id, box, visible fraction)
    for p in read_lines(os.path.join(a.sequence, "boxes.txt"), 8, "pass a yolo_slam_synth sequence folder"):
        if p[2] == "person":
            people[round(float(p[0]), 3)].append((int(p[1]), tuple(map(float, p[3:7])), float(p[7])))
    screened = collections.defaultdict(list)  # rgb stamp -> (box, tracked)
    for p in read_lines(os.path.join(a.run, "boxes_screened.txt"), 9,
                        "run yolo_slam_run in mode detect or detect+geometry (it writes boxes_screened.txt)"):
        screened[round(float(p[0]), 3)].append((tuple(map(float, p[3:7])), p[8] == "1"))
    total = collections.Counter()
    boxed = collections.Counter()
    tracked_only = 0
    missing = collections.Counter()  # person id -> frames missed in a row so far
    runs = collections.Counter()     # run-length label -> missed person-frames
    def close_run(pid):
        n = missing.pop(pid, 0)
        for lo, hi, label in RUN_BINS:
            if lo <= n <= hi:
                runs[label] += n
    for stamp in sorted(people):
        present = set()
        for pid, box, visible in people[stamp]:
            if visible < a.min_visible:
                continue
            present.add(pid)
            bin_ = next(i for i, hi in enumerate(VISIBLE_BINS[1:]) if visible < hi)
            total[bin_] += 1
            hits = [tracked for b, tracked in screened.get(stamp, []) if iou(box, b) >= a.iou]
            if hits:
                boxed[bin_] += 1
                tracked_only += all(hits)
                close_run(pid)
            else:
                missing[pid] += 1
        for pid in [p for p in missing if p not in present]:
            close_run(pid)
    for pid in list(missing):
        close_run(pid)
    n, k = sum(total.values()), sum(boxed.values())
    if n == 0:
        sys.exit("error: no person at least --min-visible visible in this sequence")
    print(f"person-frames (visible >= {a.min_visible}): {n}; with a box of their own (IoU >= {a.iou}): "
          f"{k} ({100.0 * k / n:.1f} %), {tracked_only} of them only by a tracked box")
    print("| visible fraction | person-frames | with a box |\n|---|---|---|")
    for i in sorted(total):
        print(f"| {VISIBLE_BINS[i]:.1f}-{min(1.0, VISIBLE_BINS[i + 1]):.1f} | {total[i]} | "
              f"{boxed[i]} ({100.0 * boxed[i] / total[i]:.1f} %) |")
    print("| misses lasting (frames) | " + " | ".join(label for _, _, label in RUN_BINS) + " |")
    print("|---" * (len(RUN_BINS) + 1) + "|")
    print("| person-frames | " + " | ".join(str(runs[label]) for _, _, label in RUN_BINS) + " |")


if __name__ == "__main__":
    main()
