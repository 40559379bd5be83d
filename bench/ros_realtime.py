#!/usr/bin/python3
"""The ROS graph against a bag played at rate 1, as on a robot: how many frames get a pose,
the latency from image stamp to published pose, frames dropped, and the ATE.

usage: bench/ros_realtime.py SEQ_DIR [--bag BAG] [--rate 1.0] [--out DIR] [--launch-arg k:=v ...]

SEQ_DIR is a TUM folder with groundtruth.txt (yolo_slam_synth output); the bag is made from it
with scripts/tum_to_bag.py (as OUT/sequence.bag, or as --bag when that file does not exist yet). Runs `roslaunch yolo_slam tum_bag.launch`
(source build/ws/devel/setup.bash first), reads /diagnostics until playback has ended and the
graph has drained, saves the trajectory through /yolo_slam/save_trajectory and evaluates it
with yolo_slam_eval. Prints one JSON object (also written to OUT/ros_realtime.json), with the
machine's speed measured before the run (orb_extraction_gauge_ms: features_bench's median).
"""
import argparse
import json
import os
import signal
import struct
import subprocess
import sys
import time

import rospy
from diagnostic_msgs.msg import DiagnosticArray
from geometry_msgs.msg import PoseStamped

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(HERE)
BIN = os.path.join(REPO, "build", "ws", "devel", "lib", "yolo_slam")
START_DELAY_S = 3.0   # tum_bag.launch's start_delay
DRAIN_QUIET_S = 5.0   # the graph has drained when the Slam nodelet received nothing for this long


def frames_in(seq):
    with open(os.path.join(seq, "associations.txt")) as f:
        return sum(1 for line in f if line.strip() and not line.startswith("#"))


def write_latencies(path, seen, what):
    with open(path, "w") as f:
        f.write("# image_stamp_s latency_ms (ROS clock when the %s message arrived here, minus the stamp)\n" % what)
        for stamp, now in seen:
            f.write("%.6f %.1f\n" % (stamp, (now - stamp) * 1000.0))


def speed_gauge():
    """The machine's speed before the run: this VM's single-thread speed has varied 2.3x within
    an hour, so latencies mean something only next to it. ORB extraction of the shared TUM frame,
    median ms (features_bench), or None when it cannot run."""
    try:
        out = subprocess.run([os.path.join(BIN, "features_bench")], capture_output=True, text=True, timeout=120)
    except (OSError, subprocess.TimeoutExpired):
        return None
    for line in out.stdout.splitlines():
        if line.startswith("extract"):
            return float(line.split()[2])
    return None


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("seq")
    ap.add_argument("--bag")
    ap.add_argument("--rate", type=float, default=1.0)
    ap.add_argument("--out", default="/tmp/yolo_slam_ros_realtime")
    ap.add_argument("--launch-arg", action="append", default=[])
    ap.add_argument("--stage-latency", action="store_true",
                    help="also record the Screening nodelet's output (yolo_slam/keypoint_frame) per message "
                         "in OUT/keypoint_frame_latency.txt; the graph then serialises it for this process")
    a = ap.parse_args()
    os.makedirs(a.out, exist_ok=True)
    bag = a.bag or os.path.join(a.out, "sequence.bag")
    if not os.path.exists(bag):
        subprocess.check_call([os.path.join(REPO, "scripts", "tum_to_bag.py"), a.seq, bag])
    frames = frames_in(a.seq)
    gauge_ms = speed_gauge()
    traj = os.path.join(a.out, "CameraTrajectory.txt")
    if os.path.exists(traj):
        os.remove(traj)

    launch = subprocess.Popen(["roslaunch", "yolo_slam", "tum_bag.launch", "bag:=" + bag, "rate:=%g" % a.rate,
                               "trajectory_path:=" + traj] + a.launch_arg,
                              stdout=open(os.path.join(a.out, "launch.log"), "w"), stderr=subprocess.STDOUT,
                              preexec_fn=os.setsid)
    diag = {}

    def on_diag(msg):
        for st in msg.status:
            diag[st.name] = {kv.key: kv.value for kv in st.values}

    poses_seen = []  # (image stamp, ROS clock on arrival) of every pose message, seconds

    def on_pose(msg):
        poses_seen.append((msg.header.stamp.to_sec(), rospy.get_rostime().to_sec()))

    frames_seen = []  # the same for the keypoint frames (--stage-latency)

    def on_frame(msg):
        _, secs, nsecs = struct.unpack_from("<III", msg._buff, 0)  # std_msgs/Header: seq, stamp
        frames_seen.append((secs + nsecs * 1e-9, rospy.get_rostime().to_sec()))

    def slam_diag():
        return next((v for k, v in diag.items() if "slam" in k and "tracking" in k), {})

    try:
        time.sleep(2.0)  # the master
        rospy.init_node("ros_realtime_bench", anonymous=True, disable_signals=True)
        rospy.Subscriber("/diagnostics", DiagnosticArray, on_diag)
        rospy.Subscriber("/yolo_slam/pose", PoseStamped, on_pose, queue_size=1000, tcp_nodelay=True)
        if a.stage_latency:
            rospy.Subscriber("/yolo_slam/keypoint_frame", rospy.AnyMsg, on_frame, queue_size=1000, tcp_nodelay=True)
        play_s = frames / 30.0 / a.rate
        deadline = time.time() + 60 + START_DELAY_S + play_s * 3
        last_received, last_change = -1, time.time()
        while time.time() < deadline:
            time.sleep(0.5)
            if launch.poll() is not None:
                sys.stderr.write("ros_realtime: the launch ended early (exit %d); see %s\n"
                                 % (launch.returncode, os.path.join(a.out, "launch.log")))
                break
            received = int(slam_diag().get("received", "0"))
            if received != last_received:
                last_received, last_change = received, time.time()
            elif received > 0 and time.time() - last_change > DRAIN_QUIET_S:
                break
        time.sleep(1.5)  # one more diagnostics round
        subprocess.call(["rosservice", "call", "/yolo_slam/save_trajectory", "path: '%s'" % traj],
                        stdout=subprocess.DEVNULL)
    finally:
        os.killpg(os.getpgid(launch.pid), signal.SIGINT)
        try:
            launch.wait(timeout=30)
        except subprocess.TimeoutExpired:
            os.killpg(os.getpgid(launch.pid), signal.SIGKILL)

    s = slam_diag()
    scr = next((v for k, v in diag.items() if "screening" in k), {})
    poses = sum(1 for line in open(traj) if line.strip() and not line.startswith("#")) if os.path.exists(traj) else 0
    ate = None
    if poses >= 2:
        out = subprocess.run([os.path.join(BIN, "yolo_slam_eval"), "ate", os.path.join(a.seq, "groundtruth.txt"),
                              traj, "--json"], capture_output=True, text=True)
        if out.returncode == 0:
            ate = json.loads(out.stdout).get("rmse")
    result = {
        "frames": frames, "rate": a.rate, "poses": poses,
        "posed_fraction": round(poses / frames, 4) if frames else None,
        "latency_median_ms": float(s.get("latency_median_ms", "nan")),
        "latency_p95_ms": float(s.get("latency_p95_ms", "nan")),
        "slam": s, "screening": scr, "ate_rmse_m": ate,
        "load": open("/proc/loadavg").read().split()[:3],
        "orb_extraction_gauge_ms": gauge_ms,
    }
    write_latencies(os.path.join(a.out, "pose_latency.txt"), poses_seen, "pose")
    if a.stage_latency:
        write_latencies(os.path.join(a.out, "keypoint_frame_latency.txt"), frames_seen, "keypoint frame")
    with open(os.path.join(a.out, "ros_realtime.json"), "w") as f:
        json.dump(result, f, indent=2)
    print(json.dumps(result, indent=2))
    return 0 if poses > 0 else 1


if __name__ == "__main__":
    sys.exit(main())
