#pragma once
// Screening beyond the boxes: the pixels of each person found in a box, grown by
// depth continuity from the person's keypoints over the depth image, a little past the box.
// Three rules read the mask: keypoints with depth outside every box that lie on it are the
// person's (a detector box cuts off an arm, a head or a carried object); keypoints with depth
// inside a box that lie on it at a depth off that box's person are another person's, standing
// behind the boxed one beyond their own box (Screening.maskInBoxes); and keypoints without
// depth near it sit in the depth holes of the person's outline and hair (Screening.growOutside,
// Screening.noDepthHoleRadius).
#include "yolo_slam/features/feature_frame.h"

#include <opencv2/core.hpp>

#include <cstdint>
#include <vector>

namespace yolo_slam {
namespace screening {

// One person to grow: the pixels of its keypoints with depth (seeds), their depth range and
// the rectangle the growth may not leave.
struct PersonSeeds {
  std::vector<cv::Point2f> pts;
  float lo = 0.f, hi = 0.f;  // metres; grown pixels stay within [lo, hi]
  cv::Rect2f limit;          // image pixels
};

// The person pixels: a mask of ceil(size / kPersonMaskStride) (CV_8U, 255 = person), grown from
// each seed over 4-neighbours with valid depth in [lo, hi] whose depth differs from the
// neighbour it is reached from by less than kPersonMaskStepPerM times the depth. depth_m is
// CV_32FC1 metres (<= 0: no depth).
cv::Mat growPersonMask(const cv::Mat& depth_m, const std::vector<PersonSeeds>& people);

// Distance in image pixels from every mask cell to the nearest person cell (CV_32F, mask size);
// a large value everywhere when the mask is empty.
cv::Mat personDistance(const cv::Mat& mask);

// The distance of image point p to the person pixels (personDistance sampled at p).
float distanceAt(const cv::Mat& distance, const cv::Point2f& p);

// Whether image point p lies on a person cell of the mask (false outside it).
bool personCellAt(const cv::Mat& mask, const cv::Point2f& p);

// Rows (y) and columns (x) of the image per mask cell: the growth works at half resolution, a
// person's outline moves by more than a pixel between frames anyway.
constexpr int kPersonMaskStride = 2;
// Depth continuity between neighbouring cells, as a fraction of the depth: a person's surface
// changes by a few centimetres per cell, the step from a person to what is behind is tens.
constexpr float kPersonMaskStepPerM = 0.03f;

// Keypoints outside every box (in_any 0), not dropped yet, with depth, on the person mask are
// marked in drop. Returns how many.
int markGrownOutside(const features::FeatureFrame& frame, const cv::Mat& mask,
                     const std::vector<uint8_t>& in_any, std::vector<uint8_t>& drop);

// A box as the in-box rule sees it: its screened region and the depth range of the person its
// screening found ([lo, hi]); keeps_all for a box without a person or left alone as flat.
struct BoxPerson {
  cv::Rect2f region;
  float lo = 0.f, hi = 0.f;
  bool keeps_all = false;
};

// Keypoints inside a box (in_any 1), not dropped, with depth, on the person mask, whose depth
// lies outside the person range of every box holding them are marked in drop (no box that
// holds them keeps all). Returns how many.
int markGrownInBoxes(const features::FeatureFrame& frame, const cv::Mat& mask,
                     const std::vector<BoxPerson>& boxes, const std::vector<uint8_t>& in_any,
                     std::vector<uint8_t>& drop);

// Keypoints outside every box without depth within radius_px of a person pixel are marked in
// drop. Returns how many.
int markHolesOutside(const features::FeatureFrame& frame, const cv::Mat& distance, double radius_px,
                     const std::vector<uint8_t>& in_any, std::vector<uint8_t>& drop);

}  // namespace screening
}  // namespace yolo_slam
