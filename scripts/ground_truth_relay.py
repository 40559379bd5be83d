#!/usr/bin/python3
"""Shows a bag's ground truth in rviz beside the SLAM estimate (as rtabmap's ground_truth_frame_id).

A TUM bag's /tf (remapped by tum_bag.launch to /tf_groundtruth, so it does not fight the SLAM
tree) carries the motion-capture chain /world -> ... -> the colour optical frame. This node
expresses that pose relative to the first one and in the SLAM map frame (whose origin is the
first base pose: base -> camera is ~base_to_camera), and publishes
  /yolo_slam/ground_truth_path  nav_msgs/Path in ~map_frame (the estimate's frame),
  tf ~map_frame -> ~ground_truth_frame (the true base pose now).
Parameters: ~map_frame (map), ~ground_truth_frame (ground_truth), ~world_frame (world),
~camera_frame (openni_rgb_optical_frame), ~base_to_camera ([0, 0, 0, -0.5, 0.5, -0.5, 0.5]).
"""
import numpy as np
import rospy
import tf2_ros
from geometry_msgs.msg import PoseStamped, TransformStamped
from nav_msgs.msg import Path
from tf2_msgs.msg import TFMessage


def matrix(t, q):
    x, y, z, w = q
    m = np.eye(4)
    m[:3, :3] = [[1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
                 [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
                 [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)]]
    m[:3, 3] = t
    return m


def quaternion(m):
    r = m[:3, :3]
    w = np.sqrt(max(0.0, 1 + r[0, 0] + r[1, 1] + r[2, 2])) / 2
    x = np.copysign(np.sqrt(max(0.0, 1 + r[0, 0] - r[1, 1] - r[2, 2])) / 2, r[2, 1] - r[1, 2])
    y = np.copysign(np.sqrt(max(0.0, 1 - r[0, 0] + r[1, 1] - r[2, 2])) / 2, r[0, 2] - r[2, 0])
    z = np.copysign(np.sqrt(max(0.0, 1 - r[0, 0] - r[1, 1] + r[2, 2])) / 2, r[1, 0] - r[0, 1])
    return x, y, z, w


class Relay:
    def __init__(self):
        self.map_frame = rospy.get_param("~map_frame", "map")
        self.gt_frame = rospy.get_param("~ground_truth_frame", "ground_truth")
        self.world = rospy.get_param("~world_frame", "world")
        self.camera = rospy.get_param("~camera_frame", "openni_rgb_optical_frame")
        b2c = rospy.get_param("~base_to_camera", [0.0, 0.0, 0.0, -0.5, 0.5, -0.5, 0.5])
        if len(b2c) != 7:
            raise rospy.ROSInitException("~base_to_camera needs 7 numbers [x, y, z, qx, qy, qz, qw]")
        self.T_bc = matrix(b2c[:3], b2c[3:])
        self.buffer = tf2_ros.Buffer(rospy.Duration(30))
        self.first = None
        self.path = Path()
        self.path.header.frame_id = self.map_frame
        self.path_pub = rospy.Publisher("/yolo_slam/ground_truth_path", Path, queue_size=1, latch=True)
        self.tf_pub = tf2_ros.TransformBroadcaster()
        rospy.Subscriber("/tf_groundtruth", TFMessage, self.on_tf, queue_size=100)

    def on_tf(self, msg):
        for t in msg.transforms:
            t.header.frame_id = t.header.frame_id.lstrip("/")
            t.child_frame_id = t.child_frame_id.lstrip("/")
            self.buffer.set_transform(t, "bag")
        stamp = msg.transforms[0].header.stamp if msg.transforms else None
        try:
            w_c = self.buffer.lookup_transform(self.world, self.camera, stamp)
        except (tf2_ros.LookupException, tf2_ros.ExtrapolationException, tf2_ros.ConnectivityException):
            return
        tr, ro = w_c.transform.translation, w_c.transform.rotation
        T_wc = matrix((tr.x, tr.y, tr.z), (ro.x, ro.y, ro.z, ro.w))
        if self.first is None:
            self.first = np.linalg.inv(T_wc)
        # Base pose in the map: the map is the first base pose, as the SLAM estimate's.
        T_map_base = self.T_bc @ self.first @ T_wc @ np.linalg.inv(self.T_bc)
        ps = PoseStamped()
        ps.header.stamp, ps.header.frame_id = stamp, self.map_frame
        ps.pose.position.x, ps.pose.position.y, ps.pose.position.z = T_map_base[:3, 3]
        q = quaternion(T_map_base)
        ps.pose.orientation.x, ps.pose.orientation.y, ps.pose.orientation.z, ps.pose.orientation.w = q
        self.path.header.stamp = stamp
        self.path.poses.append(ps)
        self.path_pub.publish(self.path)
        t = TransformStamped()
        t.header = ps.header
        t.child_frame_id = self.gt_frame
        t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = T_map_base[:3, 3]
        t.transform.rotation = ps.pose.orientation
        self.tf_pub.sendTransform(t)


if __name__ == "__main__":
    rospy.init_node("ground_truth_relay")
    Relay()
    rospy.spin()
