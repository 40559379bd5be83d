#pragma once
// The Slam nodelet's map and debug messages, built from core types: the sparse map as a
// PointCloud2, keyframes and covisibility as rviz line lists, and the debug image (boxes,
// kept and dropped keypoints, tracking state).
#include <opencv2/core.hpp>
#include <ros/time.h>
#include <sensor_msgs/PointCloud2.h>
#include <visualization_msgs/MarkerArray.h>

#include <string>

#include "yolo_slam/KeypointFrame.h"
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/slam/system.h"

namespace yolo_slam {
namespace ros1 {

// Static map points in `frame`; T_map_world places the SLAM world in it.
sensor_msgs::PointCloud2Ptr mapPointCloud(const slam::MapSnapshot& snap, const Pose& T_map_world,
                                          const std::string& frame, const ::ros::Time& stamp);

// A small camera frustum per keyframe (namespace "keyframes") and its covisibility edges
// ("covisibility"); an empty list is sent as DELETE so rviz clears it after a reset.
visualization_msgs::MarkerArrayPtr keyframeMarkers(const slam::MapSnapshot& snap, const Pose& T_map_world,
                                                   const std::string& frame, const ::ros::Time& stamp);

// Draws on `bgr` (grey when empty, the frame's size): boxes, kept keypoints as green circles,
// dropped ones as red crosses, and a status line.
cv::Mat drawDebugImage(cv::Mat bgr, const KeypointFrame& msg, const std::string& state, int inliers);

}  // namespace ros1
}  // namespace yolo_slam
