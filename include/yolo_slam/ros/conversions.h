#pragma once
// Conversions between the yolo_slam ROS messages / standard ROS messages and the ROS-free core
// types. Every function that can meet bad input (wrong encoding, empty image, inconsistent
// array sizes) throws yolo_slam::Error with a message naming the topic and the fix; the
// nodelets catch it, log a ROS error and keep running.
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <opencv2/core.hpp>

#include <string>

#include "yolo_slam/BoundingBox.h"
#include "yolo_slam/BoundingBoxes.h"
#include "yolo_slam/KeypointFrame.h"
#include "yolo_slam/common/camera.h"
#include "yolo_slam/common/geometry.h"
#include "yolo_slam/detection/box.h"
#include "yolo_slam/features/feature_frame.h"

namespace yolo_slam {
namespace ros1 {

// Boxes.
BoundingBox toMsg(const detection::Box& box);
detection::Box fromMsg(const BoundingBox& msg);
void toMsg(const detection::Boxes& boxes, BoundingBoxes& msg);  // header left untouched
detection::Boxes boxesFromMsg(const std::vector<BoundingBox>& msgs);

// Keypoint frames. toMsg copies keypoints (distorted coordinates), descriptors, depth and the
// dynamic flags; the header and depth_stamp are the caller's. fromMsg rebuilds a complete
// FeatureFrame: undistorted keypoints through `cam`, right_u = u_un - bf / depth (-1 without
// depth), stamp from the header. Throws Error if the arrays disagree in length, descriptors
// are not N x 32 bytes, or width/height are zero.
void toMsg(const features::FeatureFrame& frame, const detection::Boxes& boxes, KeypointFrame& msg);
features::FeatureFrame fromMsg(const KeypointFrame& msg, const CameraModel& cam);

// Images. `topic` only names the source in error messages.
// Colour image as a CV_8UC3 BGR cv::Mat (copied). Accepts rgb8, bgr8, rgba8, bgra8, mono8.
// Throws Error on an empty image, an inconsistent step/data size or another encoding.
cv::Mat imageToBgr(const sensor_msgs::Image& msg, const std::string& topic);
// View of a colour image as stored (no copy when the encoding is rgb8/bgr8): for feature
// extraction the caller passes the matching CameraModel::rgb_order. Same checks as above.
cv::Mat imageView(const sensor_msgs::Image& msg, const std::string& topic, bool& is_rgb);
// Depth image in CV_32F metres following REP 118: 16UC1 in millimetres (divided by
// `factor_16u`, 1000 by default), 32FC1 in metres. Invalid (0, NaN, inf) becomes 0.
cv::Mat depthToMetres(const sensor_msgs::Image& msg, const std::string& topic,
                      double factor_16u = 1000.0);

// Camera model from a CameraInfo (through image_geometry::PinholeCameraModel): for raw images
// K and the distortion (plumb_bob / rational_polynomial first 5), for rectified images
// (image_proc's image_rect*) P and no distortion, so they are not undistorted twice; size from
// the CameraInfo; bf, ThDepth and the rest from `base`. Throws Error if K (or, rectified, P) is
// all zeros, an entry is not finite, the principal point is outside the image or the size is 0.
CameraModel cameraFromInfo(const sensor_msgs::CameraInfo& info, const CameraModel& base,
                           const std::string& topic, bool rectified = false);

// The nodelets' ~rectified parameter: auto (rectified when the image topic contains
// "image_rect"), true or false. parseRectified throws Error on another value.
enum class Rectified { Auto, Yes, No };
Rectified parseRectified(const std::string& value);
bool isRectified(Rectified mode, const std::string& image_topic);

// Poses.
geometry_msgs::Pose poseToMsg(const Pose& T);
Pose poseFromMsg(const geometry_msgs::Pose& msg);
geometry_msgs::Transform transformToMsg(const Pose& T);
Pose transformFromMsg(const geometry_msgs::Transform& msg);

}  // namespace ros1
}  // namespace yolo_slam
