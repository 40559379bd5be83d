#pragma once
// Test helpers: a camera image message from a cv::Mat, and the TUM3 camera_info, for rostests
// that feed the nodelets by hand.
#include <ros/ros.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <opencv2/core.hpp>

#include <string>

inline sensor_msgs::ImagePtr toImage(const cv::Mat& m, const std::string& encoding, const ros::Time& t) {
  auto img = boost::make_shared<sensor_msgs::Image>();
  img->header.stamp = t;
  img->header.frame_id = "camera_rgb_optical_frame";
  img->width = m.cols;
  img->height = m.rows;
  img->encoding = encoding;
  img->step = static_cast<uint32_t>(m.cols * m.elemSize());
  img->data.assign(m.data, m.data + m.total() * m.elemSize());
  return img;
}

// config/TUM3.yaml's intrinsics, no distortion, 640x480.
inline sensor_msgs::CameraInfo tum3CameraInfo() {
  sensor_msgs::CameraInfo info;
  info.header.frame_id = "camera_rgb_optical_frame";
  info.width = 640;
  info.height = 480;
  info.K = {535.4, 0, 320.1, 0, 539.2, 247.6, 0, 0, 1};
  info.distortion_model = "plumb_bob";
  info.D = {0, 0, 0, 0, 0};
  return info;
}
