#pragma once
// From one RGB-D image pair to a FeatureFrame: grayscale, ORB extraction, undistortion and the
// per-keypoint depth / virtual right coordinate (ORB-SLAM2's ComputeStereoFromRGBD).
#include "yolo_slam/common/camera.h"
#include "yolo_slam/features/feature_frame.h"
#include "yolo_slam/features/orb_extractor.h"

#include <opencv2/core.hpp>

namespace yolo_slam {
namespace features {

// Converts an image to 8-bit grayscale: CV_8UC1 is used as is; CV_8UC3/CV_8UC4 are read as
// RGB(A) when rgb_order is true (Camera.RGB: 1), else as BGR(A). Throws yolo_slam::Error for
// empty images or other types.
cv::Mat toGray(const cv::Mat& image, bool rgb_order);

// image: BGR/RGB (per cam.rgb_order) or gray; depth_m: CV_32F metres registered to the image
// (0, negative or NaN = invalid), or empty for "no depth at all". Throws yolo_slam::Error when
// the depth has another type or size. Keypoints keep their detected (distorted) coordinates in
// `keypoints`, undistorted ones go to `keypoints_un`; depth is read at the rounded distorted
// keypoint pixel; right_u = u_un - bf / depth; both are -1 without valid depth; dynamic = 0.
FeatureFrame buildFeatureFrame(const OrbExtractor& orb, const CameraModel& cam,
                               const cv::Mat& image, const cv::Mat& depth_m, double stamp);

}  // namespace features
}  // namespace yolo_slam
