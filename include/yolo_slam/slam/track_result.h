#pragma once
#include "yolo_slam/common/geometry.h"

namespace yolo_slam {
namespace slam {

enum class TrackingState { NotInitialized, Ok, Lost };

struct TrackResult {
  TrackingState state = TrackingState::NotInitialized;
  Pose T_wc = Pose::Identity();   // valid (finite) only when state == Ok
  int inliers = 0;
  bool keyframe_inserted = false;
};

const char* toString(TrackingState s);

}  // namespace slam
}  // namespace yolo_slam
