#!/usr/bin/python3
"""Writes a TUM-format RGB-D sequence folder into a ROS bag laid out like the official TUM bags.

--layout tum (default), as the official bags:
topics /camera/rgb/image_color (sensor_msgs/Image, rgb8), /camera/depth/image (32FC1, metres),
/camera/rgb/camera_info and /camera/depth/camera_info (sensor_msgs/CameraInfo), /tf of type
tf/tfMessage as in the official bags (the same definition and md5 as tf2_msgs/TFMessage): the
chain /world -> /kinect (motion capture) -> /openni_camera -> /openni_rgb_frame ->
/openni_rgb_optical_frame (and /openni_camera -> /openni_depth_frame ->
/openni_depth_optical_frame), with /world -> /kinect chosen so that the colour optical frame's
pose in /world is groundtruth.txt. Depth is registered to colour: its images carry the colour
optical frame id.

--layout openni2, as openni2_launch records a camera (depth_registration:=true):
topics /camera/rgb/image_raw (rgb8), /camera/rgb/camera_info, /camera/depth_registered/image_raw
(16UC1, millimetres, REP 118) and /camera/depth_registered/camera_info, every image in
camera_rgb_optical_frame; the same ground-truth /tf as above. The mount base_link -> camera_link ->
camera_rgb_optical_frame is not in the bag: the robot (launch/openni2.launch) publishes it.

usage: scripts/tum_to_bag.py SEQUENCE_DIR OUTPUT.bag [--layout tum|openni2]
       [--fx 535.4 --fy 539.2 --cx 320.1 --cy 247.6] [--depth-factor 5000] [--max-diff 0.02]
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


class TfMessage(TFMessage):
    """tf/tfMessage, the type official TUM bags use for /tf (tf2 listeners accept it: same md5)."""
    _type = "tf/tfMessage"


# ROS optical frame (z forward, x right, y down) in its body frame (x forward, z up): x y z w.
OPTICAL_IN_BODY = (-0.5, 0.5, -0.5, 0.5)


class TumError(Exception):
    pass


MM_PER_M = 1000.0
# Topic names and frame id of each layout; depth "32FC1" is metres, "16UC1" millimetres.
LAYOUTS = {
    "tum": {"rgb": "/camera/rgb/image_color", "rgb_info": "/camera/rgb/camera_info",
            "depth": "/camera/depth/image", "depth_info": "/camera/depth/camera_info",
            "depth_encoding": "32FC1", "frame_id": "/openni_rgb_optical_frame"},
    "openni2": {"rgb": "/camera/rgb/image_raw", "rgb_info": "/camera/rgb/camera_info",
                "depth": "/camera/depth_registered/image_raw",
                "depth_info": "/camera/depth_registered/camera_info",
                "depth_encoding": "16UC1", "frame_id": "camera_rgb_optical_frame"},
}


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


def quat_mul(a, b):
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
            aw * bw - ax * bx - ay * by - az * bz)


def quat_inv(q):
    return (-q[0], -q[1], -q[2], q[3])


def transform(stamp, parent, child, xyz=(0.0, 0.0, 0.0), q=(0.0, 0.0, 0.0, 1.0)):
    t = TransformStamped()
    t.header.stamp = stamp
    t.header.frame_id = parent
    t.child_frame_id = child
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = xyz
    t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z, t.transform.rotation.w = q
    return t


def tf_chain(stamp, pose):
    """The official bags' tree for one ground-truth pose of the colour optical frame."""
    xyz, q_opt = pose[:3], pose[3:]
    q_kinect = quat_mul(q_opt, quat_inv(OPTICAL_IN_BODY))
    return TfMessage([transform(stamp, "/world", "/kinect", xyz, q_kinect),
                      transform(stamp, "/kinect", "/openni_camera"),
                      transform(stamp, "/openni_camera", "/openni_rgb_frame"),
                      transform(stamp, "/openni_rgb_frame", "/openni_rgb_optical_frame", q=OPTICAL_IN_BODY),
                      transform(stamp, "/openni_camera", "/openni_depth_frame"),
                      transform(stamp, "/openni_depth_frame", "/openni_depth_optical_frame", q=OPTICAL_IN_BODY)])


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


def depth_message(raw, depth_factor, encoding, stamp, frame_id):
    """REP 118 depth from a TUM depth PNG: 32FC1 metres (NaN = missing, as the TUM bags) or 16UC1
    millimetres (0 = missing, as openni2_camera)."""
    m = Image()
    m.header.stamp = stamp
    m.header.frame_id = frame_id
    m.height, m.width, m.encoding, m.is_bigendian = raw.shape[0], raw.shape[1], encoding, 0
    metres = raw.astype(np.float32) / depth_factor
    if encoding == "32FC1":
        metres[raw == 0] = np.nan
        m.step = 4 * raw.shape[1]
        m.data = metres.astype("<f4").tobytes()
    else:
        mm = np.clip(np.round(metres * MM_PER_M), 0, np.iinfo(np.uint16).max).astype("<u2")
        m.step = 2 * raw.shape[1]
        m.data = mm.tobytes()
    return m


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
    ap.add_argument("--layout", choices=sorted(LAYOUTS), default="tum",
                    help="topic names and depth encoding: the official TUM bags' or openni2_launch's")
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

    layout = LAYOUTS[args.layout]
    frame_id = layout["frame_id"]
    with rosbag.Bag(args.bag, "w") as bag:
        for t, v in gt:
            bag.write("/tf", tf_chain(stamp_of(t), v), stamp_of(t))
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
            bag.write(layout["rgb"], msg, stamp_of(tr))
            bag.write(layout["rgb_info"], info(tr, frame_id, w, h), stamp_of(tr))
            dm = depth_message(raw, cam["depth_factor"], layout["depth_encoding"], stamp_of(td), frame_id)
            bag.write(layout["depth"], dm, stamp_of(td))
            bag.write(layout["depth_info"], info(td, frame_id, raw.shape[1], raw.shape[0]), stamp_of(td))
    print("tum_to_bag: %d frames, %d poses, %s layout -> %s" % (len(pairs), len(gt), args.layout, args.bag))


if __name__ == "__main__":
    try:
        main()
    except (TumError, OSError) as e:
        sys.stderr.write("error: %s\n" % str(e).replace("\n", " "))
        sys.exit(1)
