#!/usr/bin/python3
"""Prints the settings file (config/TUM1.yaml, TUM2.yaml or TUM3.yaml) for a TUM bag's camera.

The bag's first colour CameraInfo is compared with each file's Camera.fx, fy, cx, cy (bags from
scripts/tum_to_bag.py carry the calibrated intrinsics). The official TUM bags carry the ROS default
Kinect intrinsics (fx = fy = 525) instead: then the bag's name (rgbd_dataset_freiburgN_...)
decides. tum_bag.launch runs it with tum:=auto; the path is printed without a newline (a
roslaunch <param command=...> value).

usage: scripts/tum_settings.py BAG [--config-dir DIR] [--tolerance PX]
       scripts/tum_settings.py --intrinsics FX FY CX CY [--name NAME]
"""
import argparse
import os
import re
import sys

TUM_CAMERAS = ("TUM1", "TUM2", "TUM3")
ROS_DEFAULT_KINECT = (525.0, 525.0, 319.5, 239.5)  # openni_camera's uncalibrated intrinsics
DEFAULT_TOLERANCE_PX = 2.0
CONFIG_DIR = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "config")


class SettingsError(Exception):
    pass


def settings_intrinsics(path):
    """fx fy cx cy of an ORB-SLAM2-style settings file."""
    text = open(path).read()
    vals = []
    for key in ("fx", "fy", "cx", "cy"):
        m = re.search(r"^Camera\.%s:\s*([-0-9.eE+]+)" % key, text, re.M)
        if not m:
            raise SettingsError("%s has no Camera.%s" % (path, key))
        vals.append(float(m.group(1)))
    return tuple(vals)


def largest_difference(a, b):
    return max(abs(x - y) for x, y in zip(a, b))


def bag_camera(bag_path):
    """fx fy cx cy of the bag's first CameraInfo, preferring a colour (rgb) topic."""
    import rosbag
    with rosbag.Bag(bag_path) as bag:
        topics = bag.get_type_and_topic_info().topics
        infos = sorted((("rgb" not in t), t) for t, v in topics.items() if v.msg_type == "sensor_msgs/CameraInfo")
        if not infos:
            raise SettingsError("%s has no sensor_msgs/CameraInfo topic" % bag_path)
        for _, msg, _ in bag.read_messages(topics=[infos[0][1]]):
            return (msg.K[0], msg.K[4], msg.K[2], msg.K[5])
    raise SettingsError("%s: no message on %s" % (bag_path, infos[0][1]))


def choose(intrinsics, name, config_dir, tolerance):
    files = {c: os.path.join(config_dir, c + ".yaml") for c in TUM_CAMERAS}
    diffs = {c: largest_difference(intrinsics, settings_intrinsics(f)) for c, f in files.items()}
    best = min(diffs, key=diffs.get)
    if diffs[best] <= tolerance:
        return files[best]
    m = re.search(r"freiburg([123])", os.path.basename(name))
    if m and largest_difference(intrinsics, ROS_DEFAULT_KINECT) <= tolerance:
        return files["TUM" + m.group(1)]
    raise SettingsError("camera fx %.1f fy %.1f cx %.1f cy %.1f of %s matches none of %s (nearest %s, %.1f px "
                        "off); pass settings:=... instead of tum:=auto"
                        % (intrinsics + (name, ", ".join(TUM_CAMERAS), best, diffs[best])))


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("bag", nargs="?")
    ap.add_argument("--intrinsics", type=float, nargs=4, metavar=("FX", "FY", "CX", "CY"))
    ap.add_argument("--name", default="", help="bag name for --intrinsics (freiburgN decides for default intrinsics)")
    ap.add_argument("--config-dir", default=CONFIG_DIR)
    ap.add_argument("--tolerance", type=float, default=DEFAULT_TOLERANCE_PX)
    args = ap.parse_args()
    if bool(args.bag) == bool(args.intrinsics):
        ap.error("give a BAG or --intrinsics")
    intrinsics = tuple(args.intrinsics) if args.intrinsics else bag_camera(args.bag)
    path = choose(intrinsics, args.bag or args.name, args.config_dir, args.tolerance)
    sys.stdout.write(os.path.normpath(path))


if __name__ == "__main__":
    try:
        main()
    except (SettingsError, OSError) as e:
        sys.stderr.write("tum_settings: error: %s\n" % e)
        sys.exit(1)
