#!/usr/bin/python3
"""Plays a bag with `rosbag play` after checking it can feed the yolo_slam graph.

tum_bag.launch starts it as a required node: a bag that is missing, unreadable, unindexed or
without messages on the image topics the graph listens to ends the launch with one line naming
the file and the fix, instead of a graph that waits forever. Once the bag has been played the
script stays up (without a clock), so the graph keeps its map, tf and trajectory until the user
stops the launch; a failure of `rosbag play` itself ends the launch.

usage: scripts/play_bag.py BAG --require TOPIC [--require TOPIC ...] [--check-only] [-- ROSBAG_PLAY_ARGS...]
"""
import argparse
import os
import signal
import subprocess
import sys
import time

EXIT_BAD_BAG = 2


class BagError(Exception):
    pass


def check_file(path):
    if not path:
        raise BagError("no bag given: pass bag:=/path/to/file.bag")
    if not os.path.exists(path):
        raise BagError("%s does not exist: pass bag:= an existing file (convert a TUM folder with "
                       "scripts/tum_to_bag.py FOLDER BAG)" % path)
    if not os.path.isfile(path):
        raise BagError("%s is not a file: pass bag:= a .bag file" % path)
    if not os.access(path, os.R_OK):
        raise BagError("%s is not readable by this user: fix its permissions" % path)


def bag_topics(path):
    """{topic: (message type, message count)} of the bag."""
    try:
        import rosbag
    except ImportError:
        raise BagError("cannot read %s: the rosbag Python module is missing (install python3-rosbag: "
                       "scripts/install_deps.sh)" % path)
    try:
        with rosbag.Bag(path) as bag:
            info = bag.get_type_and_topic_info().topics
    except rosbag.ROSBagUnindexedException:
        raise BagError("%s is not indexed (recording was cut off): run `rosbag reindex %s` first" % (path, path))
    except (rosbag.ROSBagException, IOError, OSError, ValueError) as e:
        raise BagError("%s is not a readable bag (%s): record or convert it again" % (path, e))
    return {t: (v.msg_type, v.message_count) for t, v in info.items()}


def check_topics(path, topics, required):
    missing = [t for t in required if topics.get(t, (None, 0))[1] == 0]
    if not missing:
        return
    images = sorted(t for t, (kind, n) in topics.items() if kind == "sensor_msgs/Image" and n > 0)
    found = ", ".join(images) if images else "none"
    raise BagError("%s has no messages on %s (its image topics: %s): pass rgb_topic:=... depth_topic:=... "
                   "naming them (a bag of scripts/tum_to_bag.py --layout openni2: rgb_topic:=/camera/rgb/image_raw "
                   "depth_topic:=/camera/depth_registered/image_raw)" % (path, ", ".join(missing), found))


def play(path, play_args):
    """Runs rosbag play; returns its exit code. SIGINT/SIGTERM are passed on to it."""
    # rosrun execs the player, so the signals reach it.
    proc = subprocess.Popen(["rosrun", "rosbag", "play"] + play_args + [path])

    def forward(signum, _frame):
        proc.send_signal(signum)
    signal.signal(signal.SIGINT, forward)
    signal.signal(signal.SIGTERM, forward)
    return proc.wait()


def main():
    argv = sys.argv[1:]
    play_args = []
    if "--" in argv:
        play_args = argv[argv.index("--") + 1:]
        argv = argv[:argv.index("--")]
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("bag")
    ap.add_argument("--require", action="append", default=[], metavar="TOPIC",
                    help="a topic the bag must carry messages on")
    ap.add_argument("--check-only", action="store_true", help="check the bag and exit")
    # roslaunch appends __name:= and __log:= to a node's arguments.
    args, _ = ap.parse_known_args([a for a in argv if not a.startswith("__")])
    try:
        check_file(args.bag)
        check_topics(args.bag, bag_topics(args.bag), args.require)
    except BagError as e:
        sys.stderr.write("play_bag: %s\n" % e)
        return EXIT_BAD_BAG
    if args.check_only:
        print("play_bag: %s carries %s" % (args.bag, ", ".join(args.require) or "messages"))
        return 0
    code = play(args.bag, [a for a in play_args if not a.startswith("__")])
    if code != 0:
        sys.stderr.write("play_bag: rosbag play %s exited with %d\n" % (args.bag, code))
        return code
    print("play_bag: %s played to the end; the graph stays up until you stop the launch" % args.bag)
    signal.signal(signal.SIGINT, signal.SIG_DFL)
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    while True:
        time.sleep(3600)


if __name__ == "__main__":
    sys.exit(main())
