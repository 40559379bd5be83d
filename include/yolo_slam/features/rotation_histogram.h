#pragma once
// ORB-SLAM2's rotation consistency check of keypoint matches (ORBmatcher's rotHist and
// ComputeThreeMaxima): between two views of a rigid scene every keypoint turns by about the same
// angle, so each match votes with the difference of its keypoints' orientations, and the matches
// outside the three fullest bins are dropped; the second and third bins count only when they
// hold at least a tenth of the fullest.
#include <cstddef>
#include <vector>

namespace yolo_slam {
namespace features {

constexpr int kRotationBins = 30;          // ORB-SLAM2 HISTO_LENGTH
constexpr double kMinRotationShare = 0.1;  // the 2nd and 3rd bins against the fullest

class RotationHistogram {
 public:
  explicit RotationHistogram(int bins = kRotationBins);

  // The bin of the orientation difference angle_a - angle_b (degrees).
  int bin(float angle_a, float angle_b) const;
  // Votes for `item` (an index of the caller's choosing) by its keypoints' orientations.
  void add(float angle_a, float angle_b, size_t item);
  // The items outside the dominant bins, in bin order.
  std::vector<size_t> outliers() const;

 private:
  std::vector<std::vector<size_t>> bins_;
};

}  // namespace features
}  // namespace yolo_slam
