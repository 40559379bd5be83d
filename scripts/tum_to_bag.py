#!/usr/bin/python3
"""Writes a TUM-format RGB-D sequence folder into a ROS bag laid out like the official TUM bags.

Topics: /camera/rgb/image_color (sensor_msgs/Image, rgb8), /camera/depth/image (32FC1, metres),
/camera/rgb/camera_info and /camera/depth/camera_info (sensor_msgs/CameraInfo), /tf
(tf2_msgs/TFMessage: the ground truth as world -> kinect, then the static kinect ->
openni_rgb_optical_frame identity, so the optical frame's pose in world is groundtruth.txt).

usage: scripts/tum_to_bag.py SEQUENCE_DIR OUTPUT.bag [--fx 535.4 --fy 539.2 --cx 320.1 --cy 247.6]
       [--depth-factor 5000] [--max-diff 0.02]
Intrinsics default to SEQUENCE_DIR/camera.yaml when present (yolo_slam_synth writes one),
else to the freiburg3 values above.
"""
import argparse
import os
import re
import sys

import cv2
import numpy as np
import rosbag
import rospy
from geometry_msgs.msg import TransformStamped
from sensor_msgs.msg import CameraInfo, Image
from tf2_msgs.msg import TFMessage


class TumError(Exception):
    pass


def read_list(path):
    """'stamp value...' rows of a TUM text file; '#' comments skipped."""
    if not os.path.isfile(path):
        raise TumError("%s is missing: is the folder a TUM sequence?" % path)
    rows = []
    with open(path) as f:
        for n, line in enumerate(f, 1):
            line = line.strip()
            if not line or line.startswith("#"):
                continue
            parts = line.replace(",", " ").split()
            try:
                rows.append((float(parts[0]), parts[1:]))
            except (ValueError, IndexError):
                raise TumError("%s:%d: malformed line %r" % (path, n, line))
    return rows


def associate(a, b, max_diff):
    """TUM associate.py: greedy pairing by increasing stamp difference."""
    cands = sorted((abs(x - y), x, y) for x in a for y in b if abs(x - y) < max_diff)
    used_a, used_b, out = set(), set(), []
    for _, x, y in cands:
        if x not in used_a and y not in used_b:
            used_a.add(x)
            used_b.add(y)
            out.append((x, y))
    return sorted(out)


def camera_yaml(path, defaults):
    vals = dict(defaults)
    if os.path.isfile(path):
        text = open(path).read()
        for key, name in (("Camera.fx", "fx"), ("Camera.fy", "fy"), ("Camera.cx", "cx"),
                          ("Camera.cy", "cy"), ("DepthMapFactor", "depth_factor")):
            m = re.search(r"^%s:\s*([-0-9.eE+]+)" % re.escape(key), text, re.M)
            if m:
                vals[name] = float(m.group(1))
    return vals


def stamp_of(t):
    return rospy.Time.from_sec(t)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("sequence")
    ap.add_argument("bag")
    ap.add_argument("--fx", type=float)
    ap.add_argument("--fy", type=float)
    ap.add_argument("--cx", type=float)
    ap.add_argument("--cy", type=float)
    ap.add_argument("--depth-factor", type=float)
    ap.add_argument("--max-diff", type=float, default=0.02)
    args = ap.parse_args()
    seq = args.sequence
    cam = camera_yaml(os.path.join(seq, "camera.yaml"),
                      {"fx": 535.4, "fy": 539.2, "cx": 320.1, "cy": 247.6, "depth_factor": 5000.0})
    for k in ("fx", "fy", "cx", "cy", "depth_factor"):
        v = getattr(args, k)
        if v is not None:
            cam[k] = v
    if cam["depth_factor"] <= 0:
        raise TumError("--depth-factor must be > 0")

    rgb = {t: v[0] for t, v in read_list(os.path.join(seq, "rgb.txt"))}
    depth = {t: v[0] for t, v in read_list(os.path.join(seq, "depth.txt"))}
    gt_path = os.path.join(seq, "groundtruth.txt")
    gt = []
    if os.path.isfile(gt_path):
        for t, v in read_list(gt_path):
            if len(v) != 7:
                raise TumError("%s: pose at %.6f needs 'tx ty tz qx qy qz qw'" % (gt_path, t))
            gt.append((t, [float(x) for x in v]))
    pairs = associate(sorted(rgb), sorted(depth), args.max_diff)
    if not pairs:
        raise TumError("%s: no rgb/depth pair within %.3f s" % (seq, args.max_diff))

    def info(t, frame, w, h):
        ci = CameraInfo()
        ci.header.stamp = stamp_of(t)
        ci.header.frame_id = frame
        ci.width, ci.height = w, h
        ci.distortion_model = "plumb_bob"
        ci.D = [0.0] * 5
        ci.K = [cam["fx"], 0, cam["cx"], 0, cam["fy"], cam["cy"], 0, 0, 1]
        ci.R = [1, 0, 0, 0, 1, 0, 0, 0, 1]
        ci.P = [cam["fx"], 0, cam["cx"], 0, 0, cam["fy"], cam["cy"], 0, 0, 0, 1, 0]
        return ci

    frame_id = "/openni_rgb_optical_frame"
    with rosbag.Bag(args.bag, "w") as bag:
        for t, v in gt:
            tf = TransformStamped()
            tf.header.stamp = stamp_of(t)
            tf.header.frame_id = "/world"
            tf.child_frame_id = "/kinect"
            (tf.transform.translation.x, tf.transform.translation.y, tf.transform.translation.z,
             tf.transform.rotation.x, tf.transform.rotation.y, tf.transform.rotation.z,
             tf.transform.rotation.w) = v
            opt = TransformStamped()
            opt.header.stamp = stamp_of(t)
            opt.header.frame_id = "/kinect"
            opt.child_frame_id = frame_id
            opt.transform.rotation.w = 1.0
            bag.write("/tf", TFMessage([tf, opt]), stamp_of(t))
        for tr, td in pairs:
            rp, dp = os.path.join(seq, rgb[tr]), os.path.join(seq, depth[td])
            im = cv2.imread(rp, cv2.IMREAD_COLOR)
            if im is None:
                raise TumError("cannot read %s" % rp)
            raw = cv2.imread(dp, cv2.IMREAD_ANYDEPTH)
            if raw is None or raw.dtype != np.uint16:
                raise TumError("cannot read %s as a 16-bit depth PNG" % dp)
            h, w = im.shape[:2]
            msg = Image()
            msg.header.stamp = stamp_of(tr)
            msg.header.frame_id = frame_id
            msg.height, msg.width, msg.encoding, msg.is_bigendian = h, w, "rgb8", 0
            msg.step = 3 * w
            msg.data = cv2.cvtColor(im, cv2.COLOR_BGR2RGB).tobytes()
            bag.write("/camera/rgb/image_color", msg, stamp_of(tr))
            bag.write("/camera/rgb/camera_info", info(tr, frame_id, w, h), stamp_of(tr))
            metres = raw.astype(np.float32) / cam["depth_factor"]
            metres[raw == 0] = np.nan  # TUM bags mark missing depth with NaN
            dm = Image()
            dm.header.stamp = stamp_of(td)
            dm.header.frame_id = frame_id
            dm.height, dm.width, dm.encoding, dm.is_bigendian = raw.shape[0], raw.shape[1], "32FC1", 0
            dm.step = 4 * raw.shape[1]
            dm.data = metres.astype("<f4").tobytes()
            bag.write("/camera/depth/image", dm, stamp_of(td))
            bag.write("/camera/depth/camera_info", info(td, frame_id, raw.shape[1], raw.shape[0]), stamp_of(td))
    print("tum_to_bag: %d frames, %d poses -> %s" % (len(pairs), len(gt), args.bag))


if __name__ == "__main__":
    try:
        main()
    except (TumError, OSError) as e:
        sys.stderr.write("error: %s\n" % str(e).replace("\n", " "))
        sys.exit(1)
