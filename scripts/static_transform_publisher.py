#!/usr/bin/python3
"""Publishes static transforms on /tf_static, as tf2_ros's static_transform_publisher (Debian's
tf2_ros packages do not ship that executable).

usage: static_transform_publisher.py x y z yaw pitch roll parent child
       static_transform_publisher.py x y z qx qy qz qw parent child [x y z qx qy qz qw parent child ...]
Several quaternion groups publish a chain from one node (one latched /tf_static message).
"""
import math
import sys

import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped

EULER_ARGS = 8       # x y z yaw pitch roll parent child
QUATERNION_ARGS = 9  # x y z qx qy qz qw parent child


def quaternion_from_ypr(yaw, pitch, roll):
    """x y z w of the rotation yaw about z, then pitch about y, then roll about x (tf's order)."""
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    return (sr * cp * cy - cr * sp * sy,
            cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy,
            cr * cp * cy + sr * sp * sy)


def transform(values, q, parent, child):
    t = TransformStamped()
    t.header.stamp = rospy.Time.now()
    t.header.frame_id = parent
    t.child_frame_id = child
    t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = values[:3]
    norm = math.sqrt(sum(c * c for c in q))
    if norm == 0:
        raise ValueError("the quaternion of %s -> %s is zero" % (parent, child))
    (t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z,
     t.transform.rotation.w) = (c / norm for c in q)
    return t


def parse(args):
    if len(args) == EULER_ARGS:
        v = [float(a) for a in args[:6]]
        return [transform(v, quaternion_from_ypr(*v[3:6]), args[6], args[7])]
    if not args or len(args) % QUATERNION_ARGS:
        raise ValueError("expected 'x y z yaw pitch roll parent child' or groups of "
                         "'x y z qx qy qz qw parent child', got %d arguments" % len(args))
    out = []
    for i in range(0, len(args), QUATERNION_ARGS):
        g = args[i:i + QUATERNION_ARGS]
        v = [float(a) for a in g[:7]]
        out.append(transform(v, v[3:7], g[7], g[8]))
    return out


def main():
    rospy.init_node("static_transform_publisher", anonymous=True)
    try:
        transforms = parse(rospy.myargv(sys.argv)[1:])
    except ValueError as e:
        rospy.logfatal("static_transform_publisher: %s", e)
        sys.exit(1)
    broadcaster = tf2_ros.StaticTransformBroadcaster()
    broadcaster.sendTransform(transforms)
    rospy.spin()


if __name__ == "__main__":
    main()
